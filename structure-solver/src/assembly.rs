//! `FeModel`: an assembled finite-element structure implementing `Model` (DESIGN §6).
//!
//! Six dofs per node `[ux, uy, uz, θx, θy, θz]`; rotations are stored as matrices and updated
//! by spatial spins, `R ← exp([δθ]×) R`. Constraints: fixed dofs, symmetry planes normal to a
//! global axis (`u·n = 0`, rotation only about `n`), prescribed translations and rotations
//! over time (a prescribed rotation dof accumulates its spins). Loads: point loads, gravity,
//! follower pressure on shells and an external nodal array filled by the coupling. Each load
//! scales with a `Curve` of time; static solves use `t` as the load factor.
//!
//! Parts: elastic shells, J2 shells integrated through the thickness (MITC4, DKT), beams,
//! tets, and the explicit-only one-point BT4 shells, which have no tangent (static and
//! implicit solvers return an error for a model holding them).

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

use faer::sparse::Triplet;

use crate::elements::bt4::{Bt4, Bt4Settings};
pub use crate::elements::RotaryInertia;
use crate::elements::{BeamSection, Element, ElementKind, ShellSection, ShellYield};
use crate::material::{Elastic, Material, ThicknessRule, J2};
use crate::mesh::{CellKind, Mesh};
use crate::model::Model;

/// A scalar function of time multiplying a load or a prescribed value.
#[derive(Debug, Clone, PartialEq)]
pub enum Curve {
    /// 1 at all times.
    Constant,
    /// `t` (a static load factor).
    Linear,
    /// Piecewise linear through `(t, value)` points, constant outside.
    Table(Vec<(f64, f64)>),
}

impl Curve {
    pub fn at(&self, t: f64) -> f64 {
        match self {
            Curve::Constant => 1.0,
            Curve::Linear => t,
            Curve::Table(p) => {
                if p.is_empty() {
                    return 0.0;
                }
                if t <= p[0].0 {
                    return p[0].1;
                }
                for w in p.windows(2) {
                    if t <= w[1].0 {
                        let s = (t - w[0].0) / (w[1].0 - w[0].0);
                        return w[0].1 + s * (w[1].1 - w[0].1);
                    }
                }
                p[p.len() - 1].1
            }
        }
    }
}

/// What a mesh cell becomes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Part {
    Shell(ShellSection),
    /// A shell of a J2 material integrated through the thickness (MITC4 or DKT).
    ShellJ2(ShellSection, ShellYield),
    /// A one-point Belytschko-Tsay shell (`elements::bt4`), elastic or J2 at the thickness
    /// points of the yield (5 Gauss points when elastic): explicit only, it has no tangent,
    /// so static and implicit solves refuse a model holding one. One material per model.
    Bt4(ShellSection, Option<ShellYield>),
    /// A beam whose local `y` axis is `up` projected normal to it.
    Beam(BeamSection, [f64; 3]),
    /// A solid of an elastic or J2 material.
    Solid(Material),
}

#[derive(Debug, thiserror::Error)]
pub enum AssemblyError {
    #[error("cell {cell}: a {kind:?} cannot carry {part}")]
    Mismatch { cell: usize, kind: CellKind, part: &'static str },
    #[error("node {node} out of range ({n} nodes)")]
    NodeRange { node: usize, n: usize },
    #[error("cell {cell}: BT4 shells of one model share one material and thickness rule")]
    Bt4Material { cell: usize },
}

#[derive(Debug, Clone)]
struct State {
    x: Vec<Vector3<f64>>,
    r: Vec<Matrix3<f64>>,
    /// Accumulated spins (only read for prescribed rotation dofs).
    spin_sum: Vec<Vector3<f64>>,
    /// Material state of all elements, flat; element `e` owns
    /// `state_offsets[e]..state_offsets[e + 1]` (tets: one point; J2 shells: every thickness
    /// point; elastic elements: nothing).
    material: Vec<f64>,
}

/// An assembled finite-element model.
#[derive(Debug, Clone)]
pub struct FeModel {
    x0: Vec<Vector3<f64>>,
    trial: State,
    committed: State,
    elements: Vec<Element>,
    state_offsets: Vec<usize>,
    /// Node lists of all mesh cells (pressure loads act on cells).
    cells: Vec<Vec<usize>>,
    /// Mesh cell of each element.
    element_cell: Vec<usize>,
    /// The explicit-only BT4 shells, if any.
    bt4: Option<Bt4Part>,
    rotary: RotaryInertia,
    mass: Vec<f64>,
    constrained: Vec<bool>,
    prescribed: Vec<(usize, f64, Curve)>,
    point_loads: Vec<(usize, f64, Curve)>,
    pressures: Vec<(Vec<usize>, f64, Curve)>,
    gravity: Option<([f64; 3], Curve)>,
    external: Vec<f64>,
    dt_crit: f64,
}

/// The BT4 shells of a model with their work arrays.
#[derive(Debug, Clone)]
struct Bt4Part {
    shells: Bt4,
    /// Positions and the increment since the last commit, in the layout `Bt4` reads.
    x: Vec<[f64; 3]>,
    du: Vec<f64>,
    /// A trial state was computed since the last commit or revert.
    evaluated: bool,
}

fn gather<T: Copy>(all: &[T], nodes: &[usize]) -> Vec<T> {
    nodes.iter().map(|&n| all[n]).collect()
}

impl FeModel {
    /// Builds the model of `mesh`, every cell becoming the element `part(cell index)` says.
    pub fn new(mesh: &Mesh, part: impl Fn(usize) -> Part) -> Result<Self, AssemblyError> {
        let nn = mesh.nodes.len();
        let x0: Vec<Vector3<f64>> = mesh.nodes.iter().map(|p| Vector3::from(*p)).collect();
        let mut elements = Vec::with_capacity(mesh.cells.len());
        let mut element_cell = Vec::with_capacity(mesh.cells.len());
        let mut bt4_conn = Vec::new();
        let mut bt4_h = Vec::new();
        let mut bt4_material: Option<(J2, usize)> = None;
        for (ci, cell) in mesh.cells.iter().enumerate() {
            if let Some(&bad) = cell.nodes.iter().find(|&&n| n >= nn) {
                return Err(AssemblyError::NodeRange { node: bad, n: nn });
            }
            if let (CellKind::Quad4, Part::Bt4(s, y)) = (cell.kind, part(ci)) {
                let j2 = J2 {
                    elastic: Elastic { e: s.e, nu: s.nu, rho: s.rho },
                    sigma_y: y.map_or(f64::INFINITY, |y| y.sigma_y),
                    h: y.map_or(0.0, |y| y.hardening),
                };
                let mat = (j2, y.map_or(5, |y| y.points));
                if *bt4_material.get_or_insert(mat) != mat {
                    return Err(AssemblyError::Bt4Material { cell: ci });
                }
                let nd = &cell.nodes;
                bt4_conn.push([nd[0], nd[1], nd[2], nd[3]].map(|n| n as u32));
                bt4_h.push(s.h);
                continue;
            }
            let p = gather(&x0, &cell.nodes);
            let nd = &cell.nodes;
            let (shell, yield_) = match part(ci) {
                Part::Shell(s) => (Some(s), None),
                Part::ShellJ2(s, y) => (Some(s), Some(y)),
                _ => (None, None),
            };
            let el = match (cell.kind, part(ci)) {
                (CellKind::Quad4, Part::Shell(_) | Part::ShellJ2(..)) => {
                    let s = shell.expect("a shell part");
                    let x = [p[0], p[1], p[2], p[3]];
                    Element::quad4([nd[0], nd[1], nd[2], nd[3]], &x, &s, yield_)
                }
                (CellKind::Tri3, Part::Shell(_) | Part::ShellJ2(..)) => {
                    let s = shell.expect("a shell part");
                    Element::tri3([nd[0], nd[1], nd[2]], &[p[0], p[1], p[2]], &s, yield_)
                }
                (CellKind::Line2, Part::Beam(s, up)) => {
                    Element::beam2([nd[0], nd[1]], &[p[0], p[1]], Vector3::from(up), &s)
                }
                (CellKind::Tet4, Part::Solid(mat)) => {
                    Element::tet4([nd[0], nd[1], nd[2], nd[3]], &[p[0], p[1], p[2], p[3]], mat)
                }
                (kind, p) => {
                    let part = match p {
                        Part::Shell(_) | Part::ShellJ2(..) => "a shell section",
                        Part::Bt4(..) => "a BT4 shell (quadrilaterals only)",
                        Part::Beam(..) => "a beam section",
                        Part::Solid(_) => "a solid material",
                    };
                    return Err(AssemblyError::Mismatch { cell: ci, kind, part });
                }
            };
            elements.push(el);
            element_cell.push(ci);
        }
        // dofs without stiffness: unused nodes, rotations of solid-only nodes
        let mut constrained = vec![true; 6 * nn];
        for e in &elements {
            for &n in &e.nodes {
                let k = if e.has_rotations() { 6 } else { 3 };
                constrained[6 * n..6 * n + k].fill(false);
            }
        }
        for c in &bt4_conn {
            for &n in c {
                constrained[6 * n as usize..6 * n as usize + 6].fill(false);
            }
        }
        let bt4 = bt4_material.map(|(material, points)| {
            let settings = Bt4Settings {
                rule: ThicknessRule::gauss(points),
                rotary: RotaryInertia::Physical,
                ..Bt4Settings::default()
            };
            Bt4Part {
                shells: Bt4::new(bt4_conn, bt4_h, material, settings),
                x: vec![[0.0; 3]; nn],
                du: vec![0.0; 6 * nn],
                evaluated: false,
            }
        });
        let mut state_offsets = vec![0];
        for e in &elements {
            state_offsets.push(state_offsets[state_offsets.len() - 1] + e.n_state());
        }
        let state = State {
            x: x0.clone(),
            r: vec![Matrix3::identity(); nn],
            spin_sum: vec![Vector3::zeros(); nn],
            material: vec![0.0; state_offsets[elements.len()]],
        };
        let mut m = FeModel {
            x0,
            trial: state.clone(),
            committed: state,
            elements,
            state_offsets,
            cells: mesh.cells.iter().map(|c| c.nodes.clone()).collect(),
            element_cell,
            bt4,
            rotary: RotaryInertia::Physical,
            mass: vec![],
            constrained,
            prescribed: vec![],
            point_loads: vec![],
            pressures: vec![],
            gravity: None,
            external: vec![0.0; 6 * nn],
            dt_crit: 0.0,
        };
        m.set_rotary_inertia(RotaryInertia::Physical);
        Ok(m)
    }

    /// The elements, in mesh cell order.
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }

    /// Committed material state of element `e` (`Element::n_state` values: J2 shells
    /// `[εp_xx, εp_yy, γp_xy, α]` per thickness point, in-plane point major; tets
    /// `[εp (6), α]`).
    pub fn element_state(&self, e: usize) -> &[f64] {
        &self.committed.material[self.state_offsets[e]..self.state_offsets[e + 1]]
    }

    /// Rotary inertia of the element's nodes as used in the mass (6 per node; translations
    /// carry the element's translational mass).
    fn element_mass(&self, e: &Element) -> Vec<f64> {
        let mut m = e.mass.clone();
        if matches!(e.kind, ElementKind::Quad4 | ElementKind::Tri3) {
            // The element mass holds the physical `m h²/12`.
            for i in 0..e.nodes.len() {
                let extra = m[6 * i] * self.rotary.added_area(e.measure) / 12.0;
                for c in 3..6 {
                    m[6 * i + c] += extra;
                }
            }
        }
        m
    }

    /// Chooses the rotary inertia and recomputes the lumped mass and critical step.
    pub fn set_rotary_inertia(&mut self, rotary: RotaryInertia) {
        self.rotary = rotary;
        let mut mass = vec![0.0; self.x0.len() * 6];
        let mut w2max = 0.0f64;
        for e in &self.elements {
            let me = self.element_mass(e);
            for (i, &n) in e.nodes.iter().enumerate() {
                for c in 0..6 {
                    mass[6 * n + c] += me[6 * i + c];
                }
            }
            let x = gather(&self.x0, &e.nodes);
            w2max = w2max.max(e.max_frequency_squared(&x, &me));
        }
        self.dt_crit = if w2max > 0.0 { 2.0 / w2max.sqrt() } else { f64::INFINITY };
        if let Some(b) = &mut self.bt4 {
            b.shells.settings.rotary = rotary;
            let x0: Vec<[f64; 3]> = self.x0.iter().map(|p| [p.x, p.y, p.z]).collect();
            b.shells.lumped_mass(&x0, &mut mass);
            self.dt_crit = self.dt_crit.min(b.shells.stable_dt(&x0));
        }
        self.mass = mass;
    }

    /// Holds dofs `mask` (`[ux, uy, uz, θx, θy, θz]`) of `nodes` at zero.
    pub fn fix(&mut self, nodes: &[usize], mask: [bool; 6]) {
        for &n in nodes {
            for c in 0..6 {
                if mask[c] {
                    self.constrained[6 * n + c] = true;
                }
            }
        }
    }

    /// Symmetry about the plane normal to global axis `axis` (0, 1, 2): `u·n = 0` and
    /// rotation only about `n`.
    pub fn symmetry(&mut self, nodes: &[usize], axis: usize) {
        let mut mask = [false; 6];
        mask[axis] = true;
        mask[3 + (axis + 1) % 3] = true;
        mask[3 + (axis + 2) % 3] = true;
        self.fix(nodes, mask);
    }

    /// Prescribes dof `c` of `nodes` to `value · curve(t)`.
    pub fn prescribe(&mut self, nodes: &[usize], c: usize, value: f64, curve: Curve) {
        for &n in nodes {
            self.constrained[6 * n + c] = true;
            self.prescribed.push((6 * n + c, value, curve.clone()));
        }
    }

    /// A point load (or moment) `value · curve(t)` on dof `c` of `node`.
    pub fn point_load(&mut self, node: usize, c: usize, value: f64, curve: Curve) {
        self.point_loads.push((6 * node + c, value, curve));
    }

    /// Follower pressure `p · curve(t)` on shell cells `cells`, acting along the normal of the
    /// right-hand rule of each cell's node order.
    pub fn pressure(&mut self, cells: &[usize], p: f64, curve: Curve) {
        self.pressures.push((cells.to_vec(), p, curve));
    }

    /// Gravity acceleration `g · curve(t)`.
    pub fn gravity(&mut self, g: [f64; 3], curve: Curve) {
        self.gravity = Some((g, curve));
    }

    /// The external nodal load array (6 per node) the coupled participant fills; added to the
    /// external force at every `t` as it is.
    pub fn external_loads_mut(&mut self) -> &mut [f64] {
        &mut self.external
    }

    /// Current nodal positions.
    pub fn positions(&self) -> &[Vector3<f64>] {
        &self.trial.x
    }

    /// Current nodal rotations.
    pub fn rotations(&self) -> &[Matrix3<f64>] {
        &self.trial.r
    }

    /// Initial nodal positions.
    pub fn initial_positions(&self) -> &[Vector3<f64>] {
        &self.x0
    }

    /// Sets the trial configuration directly (tests, restarts).
    pub fn set_configuration(&mut self, x: &[Vector3<f64>], r: &[Matrix3<f64>]) {
        self.trial.x.copy_from_slice(x);
        self.trial.r.copy_from_slice(r);
    }

    /// Total pressure on each mesh cell at time `t`.
    fn cell_pressure(&self, t: f64) -> Vec<f64> {
        let mut p = vec![0.0; self.cells.len()];
        for (cells, v, c) in &self.pressures {
            let s = v * c.at(t);
            for &e in cells {
                p[e] += s;
            }
        }
        p
    }
}

/// Nodal forces of a uniform pressure `p` on a flat or warped polygon (the area vector shared
/// equally among the nodes).
fn pressure_force(p: f64, x: &[Vector3<f64>], out: &mut [f64]) {
    let a = if x.len() == 4 {
        0.5 * (x[2] - x[0]).cross(&(x[3] - x[1]))
    } else {
        0.5 * (x[1] - x[0]).cross(&(x[2] - x[0]))
    };
    let f = a * (p / x.len() as f64);
    out.fill(0.0);
    for i in 0..x.len() {
        out[6 * i..6 * i + 3].copy_from_slice(f.as_slice());
    }
}

impl Model for FeModel {
    fn n_nodes(&self) -> usize {
        self.x0.len()
    }

    fn lumped_mass(&self) -> &[f64] {
        &self.mass
    }

    fn constrained(&self) -> &[bool] {
        &self.constrained
    }

    fn prescribed(&self, t: f64, out: &mut [f64]) {
        for (d, &c) in self.constrained.iter().enumerate() {
            if c {
                out[d] = 0.0;
            }
        }
        for (d, v, c) in &self.prescribed {
            out[*d] = v * c.at(t);
        }
    }

    fn apply_increment(&mut self, du: &[f64]) {
        let s = &mut self.trial;
        for n in 0..s.x.len() {
            let d = &du[6 * n..6 * n + 6];
            s.x[n] += Vector3::new(d[0], d[1], d[2]);
            let w = Vector3::new(d[3], d[4], d[5]);
            if w != Vector3::zeros() {
                s.r[n] = crate::elements::rotation::exp(&w) * s.r[n];
                s.spin_sum[n] += w;
            }
        }
    }

    fn internal_force(&mut self, f: &mut [f64]) {
        f.fill(0.0);
        let s = &mut self.trial;
        let committed = &self.committed.material;
        // Each element's slice of the trial state, for the parallel loop.
        let mut trial_states = Vec::with_capacity(self.elements.len());
        let mut rest = s.material.as_mut_slice();
        for w in self.state_offsets.windows(2) {
            let (mine, tail) = rest.split_at_mut(w[1] - w[0]);
            trial_states.push(mine);
            rest = tail;
        }
        let (x, r) = (&s.x, &s.r);
        let offsets = &self.state_offsets;
        let parts: Vec<Vec<f64>> = self
            .elements
            .par_iter()
            .zip(trial_states.into_par_iter())
            .enumerate()
            .map(|(ei, (e, new))| {
                let mut fe = vec![0.0; 6 * e.nodes.len()];
                let old = &committed[offsets[ei]..offsets[ei + 1]];
                e.force(&gather(x, &e.nodes), &gather(r, &e.nodes), old, new, &mut fe);
                fe
            })
            .collect();
        for (e, fe) in self.elements.iter().zip(&parts) {
            for (i, &n) in e.nodes.iter().enumerate() {
                for c in 0..6 {
                    f[6 * n + c] += fe[6 * i + c];
                }
            }
        }
        if let Some(b) = &mut self.bt4 {
            // BT4 reads the end positions and the step's increment (translations and summed
            // spins since the last commit).
            let (t, c) = (&self.trial, &self.committed);
            for n in 0..t.x.len() {
                let (dx, dw) = (t.x[n] - c.x[n], t.spin_sum[n] - c.spin_sum[n]);
                b.x[n] = [t.x[n].x, t.x[n].y, t.x[n].z];
                b.du[6 * n..6 * n + 6].copy_from_slice(&[dx.x, dx.y, dx.z, dw.x, dw.y, dw.z]);
            }
            b.shells.internal_force(&b.x, &b.du, f);
            b.evaluated = true;
        }
    }

    fn external_force(&mut self, t: f64, f: &mut [f64]) {
        f.copy_from_slice(&self.external);
        for (d, v, c) in &self.point_loads {
            f[*d] += v * c.at(t);
        }
        if let Some((g, c)) = &self.gravity {
            let s = c.at(t);
            for n in 0..self.x0.len() {
                for k in 0..3 {
                    f[6 * n + k] += self.mass[6 * n + k] * g[k] * s;
                }
            }
        }
        let pc = self.cell_pressure(t);
        let mut fe = [0.0; 24];
        for (p, nodes) in pc.iter().zip(&self.cells) {
            if *p != 0.0 {
                let k = nodes.len();
                pressure_force(*p, &gather(&self.trial.x, nodes), &mut fe[..6 * k]);
                for (i, &n) in nodes.iter().enumerate() {
                    for c in 0..3 {
                        f[6 * n + c] += fe[6 * i + c];
                    }
                }
            }
        }
    }

    /// The tangent of the elements; BT4 shells add nothing (`has_tangent` is then `false`).
    fn tangent(&mut self, t: f64, out: &mut Vec<Triplet<usize, usize, f64>>) {
        out.clear();
        let pc = self.cell_pressure(t);
        let pe: Vec<f64> = self.element_cell.iter().map(|&c| pc[c]).collect();
        let s = &self.trial;
        let committed = &self.committed.material;
        let mats: Vec<nalgebra::DMatrix<f64>> = self
            .elements
            .par_iter()
            .enumerate()
            .map(|(ei, e)| {
                let x = gather(&s.x, &e.nodes);
                let r = gather(&s.r, &e.nodes);
                let st = &committed[self.state_offsets[ei]..self.state_offsets[ei + 1]];
                if pe[ei] != 0.0 {
                    let p = pe[ei];
                    let load = move |xs: &[Vector3<f64>], o: &mut [f64]| pressure_force(p, xs, o);
                    e.tangent(&x, &r, st, Some(&load))
                } else {
                    e.tangent(&x, &r, st, None)
                }
            })
            .collect();
        for (e, k) in self.elements.iter().zip(&mats) {
            let dofs: Vec<usize> = e.nodes.iter().flat_map(|&n| 6 * n..6 * n + 6).collect();
            for (a, &da) in dofs.iter().enumerate() {
                for (b, &db) in dofs.iter().enumerate() {
                    let v = k[(a, b)];
                    if v != 0.0 {
                        out.push(Triplet::new(da, db, v));
                    }
                }
            }
        }
    }

    fn commit(&mut self) {
        self.committed.clone_from(&self.trial);
        if let Some(b) = self.bt4.as_mut().filter(|b| b.evaluated) {
            b.shells.commit();
            b.evaluated = false;
        }
    }

    fn revert(&mut self) {
        self.trial.clone_from(&self.committed);
        if let Some(b) = &mut self.bt4 {
            b.evaluated = false;
        }
    }

    fn has_tangent(&self) -> bool {
        self.bt4.is_none()
    }

    fn stable_dt(&self) -> f64 {
        self.dt_crit
    }

    fn displacement(&self, out: &mut [[f64; 3]]) {
        for (n, o) in out.iter_mut().enumerate() {
            let d = self.trial.x[n] - self.x0[n];
            *o = [d.x, d.y, d.z];
        }
    }
}
