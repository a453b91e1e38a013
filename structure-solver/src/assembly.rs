//! `FeModel`: an assembled finite-element structure implementing `Model` (DESIGN §6).
//!
//! Six dofs per node `[ux, uy, uz, θx, θy, θz]`; rotations are stored as matrices and updated
//! by spatial spins, `R ← exp([δθ]×) R`. Constraints: fixed dofs, symmetry planes normal to a
//! global axis (`u·n = 0`, rotation only about `n`) or to any vector (`symmetry_plane`: a
//! linear constraint per node, reduced like the rigid bodies), prescribed translations and
//! rotations over time (a prescribed rotation dof accumulates its spins). Loads: point loads,
//! gravity, follower pressure on shells and an external nodal array filled by the coupling.
//! Each load scales with a `Curve` of time; static solves use `t` as the load factor.
//!
//! Rigid bodies and links (`rigid`): slave nodes follow a master node; the model then returns
//! reduced forces `Tᵀ f` and tangent `Tᵀ K T` (plus the geometric term of the rotating
//! offsets), marks the slave dofs constrained, and moves slaves with their master in
//! `apply_increment`, so the static and implicit solvers need nothing more; the explicit
//! integrator uses the `Model` hooks for the master's mass block and free rigid-body drift.
//! A master at a point or at the mass centre is a node appended after the mesh nodes.
//!
//! Parts: elastic shells, J2 shells integrated through the thickness (MITC4, DKT), beams,
//! tets, and the explicit-only one-point BT4 shells, which have no tangent (static and
//! implicit solvers return an error for a model holding them).

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

use faer::sparse::Triplet;

use crate::elements::bt4::{Bt4, Bt4Settings};
pub use crate::elements::RotaryInertia;
use crate::elements::{BeamSection, BeamYield, Element, ElementKind, ShellSection, ShellYield};
use crate::material::{Elastic, Material, ThicknessRule, J2};
use crate::mesh::{CellKind, Mesh};
use crate::model::Model;
use crate::rigid::{ExtraMass, RigidBody, RigidError, RigidReference};

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
    /// A beam of a J2 material by fibres (`elements::beam::FibreBeam`), `up` as for `Beam`.
    BeamJ2(BeamSection, [f64; 3], BeamYield),
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
    #[error("symmetry plane: the normal {normal:?} is not a finite non-zero vector")]
    BadNormal { normal: [f64; 3] },
    #[error("symmetry plane: node {node} belongs to a rigid body")]
    SymmetryRigid { node: usize },
    #[error("symmetry plane: node {node} has a prescribed dof")]
    SymmetryPrescribed { node: usize },
}

/// The linear constraints of skew symmetry planes at one node (`FeModel::symmetry_plane`):
/// each plane of normal `n` asks `u·n = 0` and `θ·a = θ·b = 0` (`a`, `b` spanning the plane),
/// fixed dofs ask their component to vanish. Gauss-Jordan elimination of these rows picks
/// dependent dofs (pivots) and writes the node's dofs as `u = T q`, `q` its independent dofs
/// (the node's own global components, so velocities and loads keep their meaning): the
/// reduction `Tᵀ f`, `Tᵀ K T`, `Tᵀ M T` of the rigid bodies, per node.
#[derive(Debug, Clone)]
struct SkewNode {
    node: usize,
    normals: Vec<Vector3<f64>>,
    /// The node's constrained flags before its first plane.
    base: [bool; 6],
    /// `T` (6x6, node dofs); columns of dependent dofs are zero.
    t: nalgebra::Matrix6<f64>,
    dependent: [bool; 6],
}

impl SkewNode {
    /// Eliminates the constraint rows of one 3-vector block (translations or rotations):
    /// returns the block of `T` and the dependent components.
    fn eliminate(rows: &[Vector3<f64>]) -> (Matrix3<f64>, [bool; 3]) {
        let mut a: Vec<Vector3<f64>> = rows.iter().map(|r| r / r.norm()).collect();
        let mut pivots: Vec<(usize, usize)> = Vec::new();
        let mut used_rows = vec![false; a.len()];
        loop {
            // full pivoting over unused rows and free columns
            let mut best = (0.0, 0, 0);
            for (i, r) in a.iter().enumerate() {
                if used_rows[i] {
                    continue;
                }
                for c in 0..3 {
                    if !pivots.iter().any(|p| p.1 == c) && r[c].abs() > best.0 {
                        best = (r[c].abs(), i, c);
                    }
                }
            }
            if best.0 <= 1e-10 {
                break;
            }
            let (_, i, c) = best;
            used_rows[i] = true;
            let piv = a[i] / a[i][c];
            a[i] = piv;
            for (k, r) in a.iter_mut().enumerate() {
                if k != i {
                    let f = r[c];
                    *r -= f * piv;
                }
            }
            pivots.push((i, c));
        }
        let mut t = Matrix3::identity();
        let mut dep = [false; 3];
        for &(i, c) in &pivots {
            dep[c] = true;
            // u_c + Σ_j a_ij u_j = 0 over the independent j
            for j in 0..3 {
                t[(c, j)] = if j == c { 0.0 } else { -a[i][j] };
            }
        }
        for &(_, c) in &pivots {
            for r in 0..3 {
                t[(r, c)] = 0.0;
            }
        }
        (t, dep)
    }

    /// Rebuilds `T` from the planes and the node's fixed dofs.
    fn rebuild(&mut self, fixed: &[bool]) {
        let mut tr: Vec<Vector3<f64>> = self.normals.clone();
        let mut rot = Vec::new();
        for n in &self.normals {
            let k = n.iamin();
            let a = n.cross(&Vector3::ith(k, 1.0)).normalize();
            rot.push(a);
            rot.push(n.cross(&a));
        }
        for c in 0..3 {
            if fixed[c] {
                tr.push(Vector3::ith(c, 1.0));
            }
            if fixed[3 + c] {
                rot.push(Vector3::ith(c, 1.0));
            }
        }
        let (tt, dt) = Self::eliminate(&tr);
        let (trr, dr) = Self::eliminate(&rot);
        self.t = nalgebra::Matrix6::zeros();
        self.t.fixed_view_mut::<3, 3>(0, 0).copy_from(&tt);
        self.t.fixed_view_mut::<3, 3>(3, 3).copy_from(&trr);
        self.dependent = [dt[0], dt[1], dt[2], dr[0], dr[1], dr[2]];
    }

    /// The reduced 6x6 mass block `Tᵀ diag(m) T` of the node (`m` its six lumped masses).
    fn mass(&self, m: &[f64]) -> nalgebra::Matrix6<f64> {
        let d = nalgebra::Matrix6::from_diagonal(&nalgebra::Vector6::from_column_slice(m));
        self.t.transpose() * d * self.t
    }
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
    /// Lumped mass of the model's free dofs (rigid bodies reduced to their masters).
    mass: Vec<f64>,
    /// Lumped mass of every node as the elements give it (before the rigid reduction).
    node_mass: Vec<f64>,
    constrained: Vec<bool>,
    /// Dofs fixed or prescribed by the user (the others of `constrained` have no stiffness
    /// or are rigid slaves).
    user_fixed: Vec<bool>,
    rigid: Vec<RigidBody>,
    /// Nodes on skew symmetry planes, and the entry of each node in it.
    skew: Vec<SkewNode>,
    skew_of: Vec<Option<usize>>,
    /// Rigid body of each node (master or slave), and whether it is a slave.
    body_of: Vec<Option<usize>>,
    slave: Vec<bool>,
    /// Internal force before the rigid reduction at the current configuration, if
    /// `fint_valid` (the tangent's geometric term of rigid offsets reads it).
    fint_full: Vec<f64>,
    fint_valid: bool,
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
                (CellKind::Line2, Part::BeamJ2(s, up, y)) => {
                    Element::beam2_j2([nd[0], nd[1]], &[p[0], p[1]], Vector3::from(up), &s, y)
                }
                (CellKind::Tet4, Part::Solid(mat)) => {
                    Element::tet4([nd[0], nd[1], nd[2], nd[3]], &[p[0], p[1], p[2], p[3]], mat)
                }
                (kind, p) => {
                    let part = match p {
                        Part::Shell(_) | Part::ShellJ2(..) => "a shell section",
                        Part::Bt4(..) => "a BT4 shell (quadrilaterals only)",
                        Part::Beam(..) | Part::BeamJ2(..) => "a beam section",
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
            node_mass: vec![],
            constrained,
            user_fixed: vec![false; 6 * nn],
            rigid: vec![],
            skew: vec![],
            skew_of: vec![None; nn],
            body_of: vec![None; nn],
            slave: vec![false; nn],
            fint_full: vec![],
            fint_valid: false,
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
        self.node_mass = mass;
        self.reduce_mass();
    }

    /// The lumped mass of the free dofs: rigid slaves carry nothing, masters the diagonal of
    /// their body's mass block in the current orientation (the full block acts through the
    /// `Model` mass hooks).
    fn reduce_mass(&mut self) {
        self.mass.clone_from(&self.node_mass);
        for b in &mut self.rigid {
            b.set_mass(&self.node_mass);
            let m6 = b.mass6(&self.trial.r[b.master]);
            for c in 0..6 {
                self.mass[6 * b.master + c] = m6[(c, c)];
            }
            for &s in &b.slaves {
                self.mass[6 * s..6 * s + 6].fill(0.0);
            }
        }
        for k in &self.skew {
            let d = 6 * k.node;
            let m = k.mass(&self.node_mass[d..d + 6]);
            for c in 0..6 {
                self.mass[d + c] = m[(c, c)];
            }
        }
    }

    /// Makes `nodes` a rigid body on the master `reference` with the mass and inertia of its
    /// nodes plus `extra`; returns the master node. A two-node set is a rigid link. Each node
    /// belongs to at most one body; slaves may carry no fixed or prescribed dof (define those
    /// before the body: later ones on slaves have no effect), the master may. `Point` and
    /// `MassCentre` append a node (index `n_nodes()` before the call) with six free dofs and no
    /// element; `Node` may name a node outside the set, which then joins the body. Loads on
    /// slaves (point loads, pressure, gravity, the coupling's nodal array) reach the master as
    /// a force and a moment about it.
    pub fn rigid_body(
        &mut self,
        nodes: &[usize],
        reference: RigidReference,
        extra: ExtraMass,
    ) -> Result<usize, RigidError> {
        let nn = self.x0.len();
        let mut set = nodes.to_vec();
        set.sort_unstable();
        set.dedup();
        if set.is_empty() {
            return Err(RigidError::Empty);
        }
        let mut check = set.clone();
        if let RigidReference::Node(m) = reference {
            check.push(m);
        }
        for &n in &check {
            if n >= nn {
                return Err(RigidError::NodeRange { node: n, n: nn });
            }
            if self.skew_of[n].is_some() {
                return Err(RigidError::SymmetryPlane { node: n });
            }
            if let Some(body) = self.body_of[n] {
                return Err(RigidError::TwoBodies { node: n, body });
            }
        }
        let (master, point) = match reference {
            RigidReference::Node(m) => (m, None),
            RigidReference::Point(p) => (nn, Some(Vector3::from(p))),
            RigidReference::MassCentre => {
                let c = RigidBody::centre_of(&set, &self.trial.x, &extra, &self.node_mass);
                (nn, Some(c.ok_or(RigidError::NoMass)?))
            }
        };
        let slaves: Vec<usize> = set.into_iter().filter(|&n| n != master).collect();
        for &s in &slaves {
            if let Some(dof) = (0..6).find(|&c| self.user_fixed[6 * s + c]) {
                return Err(RigidError::ConstrainedSlave { node: s, dof });
            }
        }
        let (mut x, mut r, mut node_mass) =
            (self.trial.x.clone(), self.trial.r.clone(), self.node_mass.clone());
        if let Some(p) = point {
            x.push(p);
            r.push(Matrix3::identity());
            node_mass.extend([0.0; 6]);
        }
        let body = RigidBody::new(master, slaves, &x, &r, &extra, &node_mass)?;
        if let Some(p) = point {
            self.add_node(p);
        }
        let id = self.rigid.len();
        self.body_of[master] = Some(id);
        for c in 0..6 {
            // the body gives the master inertia and, through the slaves, stiffness
            self.constrained[6 * master + c] = self.user_fixed[6 * master + c];
        }
        for &s in &body.slaves {
            self.body_of[s] = Some(id);
            self.slave[s] = true;
            self.constrained[6 * s..6 * s + 6].fill(true);
        }
        self.rigid.push(body);
        self.reduce_mass();
        self.fint_valid = false;
        Ok(master)
    }

    /// The rigid bodies, in the order they were made.
    pub fn rigid_bodies(&self) -> &[RigidBody] {
        &self.rigid
    }

    /// Appends a node at `p` (no element, six free dofs, no mass of its own).
    fn add_node(&mut self, p: Vector3<f64>) {
        self.x0.push(p);
        for s in [&mut self.trial, &mut self.committed] {
            s.x.push(p);
            s.r.push(Matrix3::identity());
            s.spin_sum.push(Vector3::zeros());
        }
        self.mass.extend([0.0; 6]);
        self.node_mass.extend([0.0; 6]);
        self.constrained.extend([false; 6]);
        self.user_fixed.extend([false; 6]);
        self.external.extend([0.0; 6]);
        self.body_of.push(None);
        self.skew_of.push(None);
        self.slave.push(false);
        if let Some(b) = &mut self.bt4 {
            b.x.push([p.x, p.y, p.z]);
            b.du.extend([0.0; 6]);
        }
    }

    /// Moves every slave with its master (positions, rotations and accumulated spins).
    fn place_slaves(&mut self, du: &[f64]) {
        let s = &mut self.trial;
        for b in &self.rigid {
            let (xm, rm) = (s.x[b.master], s.r[b.master]);
            let w = Vector3::new(du[6 * b.master + 3], du[6 * b.master + 4], du[6 * b.master + 5]);
            for (k, &n) in b.slaves.iter().enumerate() {
                (s.x[n], s.r[n]) = b.slave(k, &xm, &rm);
                s.spin_sum[n] += w;
            }
        }
    }

    /// `f ← Tᵀ f`: slave forces and moments move to their master (moment of the force about
    /// the master added); slave entries become zero.
    fn reduce_forces(&self, f: &mut [f64]) {
        let x = &self.trial.x;
        for b in &self.rigid {
            let m = b.master;
            for &s in &b.slaves {
                let force = Vector3::new(f[6 * s], f[6 * s + 1], f[6 * s + 2]);
                let moment = (x[s] - x[m]).cross(&force);
                for c in 0..3 {
                    f[6 * m + c] += f[6 * s + c];
                    f[6 * m + 3 + c] += f[6 * s + 3 + c] + moment[c];
                }
                f[6 * s..6 * s + 6].fill(0.0);
            }
        }
    }

    /// `K ← Tᵀ K T` on triplets, plus the geometric term of the rotating offsets
    /// `Σ_s [g_s]× [r_s]×` on the master's rotations (`g_s` the slave's internal minus external
    /// force, `r_s = x_s - x_m`).
    fn reduce_tangent(&mut self, t: f64, k: &mut Vec<Triplet<usize, usize, f64>>) {
        use crate::elements::rotation::spin;
        if !self.fint_valid {
            let mut f = vec![0.0; self.n_dof()];
            self.internal_force(&mut f);
        }
        let mut fext = vec![0.0; self.n_dof()];
        self.external_unreduced(t, &mut fext);
        let x = &self.trial.x;
        // per node: (master, r_s) of slaves
        let mut link: Vec<Option<(usize, Vector3<f64>)>> = vec![None; x.len()];
        for b in &self.rigid {
            for &s in &b.slaves {
                link[s] = Some((b.master, x[s] - x[b.master]));
            }
        }
        // column d of T: (reduced dof, coefficient) pairs
        let expand = |d: usize| -> ([(usize, f64); 4], usize) {
            let (n, c) = (d / 6, d % 6);
            match link[n] {
                None => ([(d, 1.0); 4], 1),
                Some((m, _)) if c >= 3 => ([(6 * m + c, 1.0); 4], 1),
                Some((m, r)) => {
                    // δu_s = δu_m - [r]× δθ_m
                    let s = -spin(&r);
                    let mut out = [(6 * m + c, 1.0); 4];
                    let mut len = 1;
                    for j in 0..3 {
                        if s[(c, j)] != 0.0 {
                            out[len] = (6 * m + 3 + j, s[(c, j)]);
                            len += 1;
                        }
                    }
                    (out, len)
                }
            }
        };
        let mut out = Vec::with_capacity(k.len());
        for e in k.iter() {
            if link[e.row / 6].is_none() && link[e.col / 6].is_none() {
                out.push(*e);
                continue;
            }
            let (rows, nr) = expand(e.row);
            let (cols, nc) = expand(e.col);
            for &(i, a) in &rows[..nr] {
                for &(j, b) in &cols[..nc] {
                    out.push(Triplet::new(i, j, a * e.val * b));
                }
            }
        }
        for (s, l) in link.iter().enumerate() {
            if let Some((m, r)) = l {
                let g = Vector3::from_fn(|c, _| self.fint_full[6 * s + c] - fext[6 * s + c]);
                let gr = spin(&g) * spin(r);
                for i in 0..3 {
                    for j in 0..3 {
                        if gr[(i, j)] != 0.0 {
                            out.push(Triplet::new(6 * m + 3 + i, 6 * m + 3 + j, gr[(i, j)]));
                        }
                    }
                }
            }
        }
        *k = out;
    }

    /// Holds dofs `mask` (`[ux, uy, uz, θx, θy, θz]`) of `nodes` at zero.
    pub fn fix(&mut self, nodes: &[usize], mask: [bool; 6]) {
        for &n in nodes {
            for c in 0..6 {
                if mask[c] {
                    self.constrained[6 * n + c] = true;
                    self.user_fixed[6 * n + c] = true;
                }
            }
            if let Some(k) = self.skew_of[n] {
                self.rebuild_skew(k);
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

    /// Symmetry about the plane of unit `normal` (any direction; normalised here) through
    /// `nodes`: `u·n = 0` and rotation only about `n`. Axis-aligned normals at nodes without a
    /// skew plane fix dofs as `symmetry` does; others constrain the node's dofs linearly
    /// (`SkewNode`: dependent dofs marked constrained, forces, tangent and mass reduced by
    /// the node's `T`, increments and dependent velocities expanded by it), so every solver
    /// respects them. A node may lie on several planes and have fixed dofs (fix before or
    /// after); it may not belong to a rigid body or carry a prescribed dof.
    pub fn symmetry_plane(
        &mut self,
        nodes: &[usize],
        normal: [f64; 3],
    ) -> Result<(), AssemblyError> {
        let n = Vector3::from(normal);
        let len = n.norm();
        if !len.is_finite() || len == 0.0 {
            return Err(AssemblyError::BadNormal { normal });
        }
        let n = n / len;
        let nn = self.x0.len();
        for &node in nodes {
            if node >= nn {
                return Err(AssemblyError::NodeRange { node, n: nn });
            }
            if self.body_of[node].is_some() {
                return Err(AssemblyError::SymmetryRigid { node });
            }
            if self.prescribed.iter().any(|p| p.0 / 6 == node) {
                return Err(AssemblyError::SymmetryPrescribed { node });
            }
        }
        let axis = (0..3).find(|&a| n[a].abs() == 1.0);
        for &node in nodes {
            match (axis, self.skew_of[node]) {
                (Some(a), None) => self.symmetry(&[node], a),
                (_, Some(k)) => {
                    self.skew[k].normals.push(n);
                    self.rebuild_skew(k);
                }
                (None, None) => {
                    let d = 6 * node;
                    let mut base = [false; 6];
                    base.copy_from_slice(&self.constrained[d..d + 6]);
                    self.skew_of[node] = Some(self.skew.len());
                    self.skew.push(SkewNode {
                        node,
                        normals: vec![n],
                        base,
                        t: nalgebra::Matrix6::identity(),
                        dependent: [false; 6],
                    });
                    self.rebuild_skew(self.skew.len() - 1);
                }
            }
        }
        self.reduce_mass();
        Ok(())
    }

    /// Recomputes skew node `k`'s `T` and its constrained flags.
    fn rebuild_skew(&mut self, k: usize) {
        let s = &mut self.skew[k];
        let d = 6 * s.node;
        s.rebuild(&self.user_fixed[d..d + 6]);
        for c in 0..6 {
            self.constrained[d + c] = s.base[c] || self.user_fixed[d + c] || s.dependent[c];
        }
    }

    /// `f ← Tᵀ f` at the skew symmetry nodes.
    fn reduce_skew_forces(&self, f: &mut [f64]) {
        for k in &self.skew {
            let d = 6 * k.node;
            let r = k.t.transpose() * nalgebra::Vector6::from_column_slice(&f[d..d + 6]);
            f[d..d + 6].copy_from_slice(r.as_slice());
        }
    }

    /// `v ← T v` at the skew symmetry nodes (dependent dofs from the independent ones).
    fn expand_skew(&self, v: &mut [f64]) {
        for k in &self.skew {
            let d = 6 * k.node;
            let r = k.t * nalgebra::Vector6::from_column_slice(&v[d..d + 6]);
            v[d..d + 6].copy_from_slice(r.as_slice());
        }
    }

    /// `K ← Tᵀ K T` on triplets at the skew symmetry nodes (`T` is constant: no geometric
    /// term).
    fn reduce_skew_tangent(&self, k: &mut Vec<Triplet<usize, usize, f64>>) {
        let expand = |d: usize| -> ([(usize, f64); 3], usize) {
            let (n, c) = (d / 6, d % 6);
            let mut out = [(d, 1.0); 3];
            let Some(s) = self.skew_of[n] else { return (out, 1) };
            let t = &self.skew[s].t;
            let mut len = 0;
            for j in 0..6 {
                if t[(c, j)] != 0.0 {
                    out[len] = (6 * n + j, t[(c, j)]);
                    len += 1;
                }
            }
            (out, len)
        };
        let mut out = Vec::with_capacity(k.len());
        for e in k.iter() {
            if self.skew_of[e.row / 6].is_none() && self.skew_of[e.col / 6].is_none() {
                out.push(*e);
                continue;
            }
            let (rows, nr) = expand(e.row);
            let (cols, nc) = expand(e.col);
            for &(i, a) in &rows[..nr] {
                for &(j, b) in &cols[..nc] {
                    out.push(Triplet::new(i, j, a * e.val * b));
                }
            }
        }
        *k = out;
    }

    /// Prescribes dof `c` of `nodes` to `value · curve(t)`.
    pub fn prescribe(&mut self, nodes: &[usize], c: usize, value: f64, curve: Curve) {
        for &n in nodes {
            self.constrained[6 * n + c] = true;
            self.user_fixed[6 * n + c] = true;
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
        self.fint_valid = false;
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
        self.fint_valid = false;
        let expanded;
        let du = if self.skew.is_empty() {
            du
        } else {
            expanded = {
                let mut v = du.to_vec();
                self.expand_skew(&mut v);
                v
            };
            &expanded
        };
        let s = &mut self.trial;
        for n in 0..s.x.len() {
            if self.slave[n] {
                continue;
            }
            let d = &du[6 * n..6 * n + 6];
            s.x[n] += Vector3::new(d[0], d[1], d[2]);
            let w = Vector3::new(d[3], d[4], d[5]);
            if w != Vector3::zeros() {
                s.r[n] = crate::elements::rotation::exp(&w) * s.r[n];
                s.spin_sum[n] += w;
            }
        }
        if !self.rigid.is_empty() {
            self.place_slaves(du);
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
        if !self.rigid.is_empty() {
            self.fint_full.clear();
            self.fint_full.extend_from_slice(f);
            self.fint_valid = true;
            self.reduce_forces(f);
        }
        self.reduce_skew_forces(f);
    }

    fn external_force(&mut self, t: f64, f: &mut [f64]) {
        self.external_unreduced(t, f);
        self.reduce_skew_forces(f);
        if self.rigid.is_empty() {
            return;
        }
        if let Some((g, c)) = &self.gravity {
            // the weight of extra masses, at their centres
            let s = c.at(t);
            for b in &self.rigid {
                let (mass, arm) = b.extra_weight(&self.trial.r[b.master]);
                if mass > 0.0 {
                    let w = Vector3::from(*g) * (mass * s);
                    let moment = arm.cross(&w);
                    for k in 0..3 {
                        f[6 * b.master + k] += w[k];
                        f[6 * b.master + 3 + k] += moment[k];
                    }
                }
            }
        }
        self.reduce_forces(f);
    }

    /// Tangent of internal minus external force, reduced by the rigid bodies.
    fn tangent(&mut self, t: f64, out: &mut Vec<Triplet<usize, usize, f64>>) {
        self.element_tangent(t, out);
        if !self.rigid.is_empty() {
            self.reduce_tangent(t, out);
        }
        if !self.skew.is_empty() {
            self.reduce_skew_tangent(out);
        }
    }

    fn apply_inverse_mass(&self, f: &[f64], a: &mut [f64]) {
        let (m, c) = (&self.mass, &self.constrained);
        for (i, a) in a.iter_mut().enumerate() {
            *a = if c[i] || m[i] <= 0.0 { 0.0 } else { f[i] / m[i] };
        }
        for b in &self.rigid {
            let d = 6 * b.master;
            let am = b.inverse_mass(&self.trial.r[b.master], &c[d..d + 6], &f[d..d + 6]);
            a[d..d + 6].copy_from_slice(am.as_slice());
        }
        for k in &self.skew {
            let d = 6 * k.node;
            let mut mk = k.mass(&self.node_mass[d..d + 6]);
            let mut rhs = nalgebra::Vector6::from_column_slice(&f[d..d + 6]);
            for i in 0..6 {
                if c[d + i] || mk[(i, i)] <= 0.0 {
                    mk.row_mut(i).fill(0.0);
                    mk.column_mut(i).fill(0.0);
                    mk[(i, i)] = 1.0;
                    rhs[i] = 0.0;
                }
            }
            let ak = mk.cholesky().map_or(nalgebra::Vector6::zeros(), |ch| ch.solve(&rhs));
            a[d..d + 6].copy_from_slice(ak.as_slice());
        }
    }

    fn mass_product(&self, v: &[f64], out: &mut [f64]) {
        for ((o, m), v) in out.iter_mut().zip(&self.mass).zip(v) {
            *o = m * v;
        }
        for b in &self.rigid {
            let d = 6 * b.master;
            let vm = nalgebra::Vector6::from_column_slice(&v[d..d + 6]);
            let p = b.mass6(&self.trial.r[b.master]) * vm;
            out[d..d + 6].copy_from_slice(p.as_slice());
        }
        for k in &self.skew {
            let d = 6 * k.node;
            let vk = nalgebra::Vector6::from_column_slice(&v[d..d + 6]);
            let p = k.mass(&self.node_mass[d..d + 6]) * vk;
            out[d..d + 6].copy_from_slice(p.as_slice());
        }
    }

    fn nondiagonal_mass(&self, out: &mut Vec<Triplet<usize, usize, f64>>) {
        out.clear();
        for b in &self.rigid {
            let d = 6 * b.master;
            let m6 = b.mass6(&self.trial.r[b.master]);
            for i in 0..6 {
                for j in 0..6 {
                    let v = if i == j { m6[(i, j)] - self.mass[d + i] } else { m6[(i, j)] };
                    if v != 0.0 {
                        out.push(Triplet::new(d + i, d + j, v));
                    }
                }
            }
        }
        for k in &self.skew {
            let d = 6 * k.node;
            let mk = k.mass(&self.node_mass[d..d + 6]);
            for i in 0..6 {
                for j in 0..6 {
                    if i != j && mk[(i, j)] != 0.0 {
                        out.push(Triplet::new(d + i, d + j, mk[(i, j)]));
                    }
                }
            }
        }
    }

    fn explicit_drift(&self, dt: f64, v_half: &mut [f64], du: &mut [f64]) {
        let (x, r) = (&self.trial.x, &self.trial.r);
        for b in &self.rigid {
            let m = b.master;
            let d = 6 * m;
            let cons = &self.constrained[d..d + 6];
            let (dx, r1) = b.drift(&r[m], cons, dt, &mut v_half[d..d + 6], &du[d..d + 6]);
            let w = crate::elements::rotation::log(&(r1 * r[m].transpose()));
            du[d..d + 3].copy_from_slice(dx.as_slice());
            du[d + 3..d + 6].copy_from_slice(w.as_slice());
            let xm1 = x[m] + dx;
            for (k, &s) in b.slaves.iter().enumerate() {
                let dxs = b.slave(k, &xm1, &r1).0 - x[s];
                du[6 * s..6 * s + 3].copy_from_slice(dxs.as_slice());
                du[6 * s + 3..6 * s + 6].copy_from_slice(w.as_slice());
                for c in 0..6 {
                    v_half[6 * s + c] = du[6 * s + c] / dt;
                }
            }
        }
    }

    fn dependent_motion(&self, v: &mut [f64], a: &mut [f64]) {
        let x = &self.trial.x;
        let v3 = |v: &[f64], i: usize| Vector3::new(v[i], v[i + 1], v[i + 2]);
        for b in &self.rigid {
            let d = 6 * b.master;
            let (vm, w, am, al) = (v3(v, d), v3(v, d + 3), v3(a, d), v3(a, d + 3));
            for &s in &b.slaves {
                let r = x[s] - x[b.master];
                let vs = vm + w.cross(&r);
                let acc = am + al.cross(&r) + w.cross(&w.cross(&r));
                v[6 * s..6 * s + 3].copy_from_slice(vs.as_slice());
                v[6 * s + 3..6 * s + 6].copy_from_slice(w.as_slice());
                a[6 * s..6 * s + 3].copy_from_slice(acc.as_slice());
                a[6 * s + 3..6 * s + 6].copy_from_slice(al.as_slice());
            }
        }
        self.expand_skew(v);
        self.expand_skew(a);
    }

    fn commit(&mut self) {
        self.committed.clone_from(&self.trial);
        if let Some(b) = self.bt4.as_mut().filter(|b| b.evaluated) {
            b.shells.commit();
            b.evaluated = false;
        }
    }

    fn revert(&mut self) {
        self.fint_valid = false;
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

impl FeModel {
    /// External force before the rigid reduction (loads on every node as given).
    fn external_unreduced(&self, t: f64, f: &mut [f64]) {
        f.copy_from_slice(&self.external);
        for (d, v, c) in &self.point_loads {
            f[*d] += v * c.at(t);
        }
        if let Some((g, c)) = &self.gravity {
            let s = c.at(t);
            for n in 0..self.x0.len() {
                for k in 0..3 {
                    f[6 * n + k] += self.node_mass[6 * n + k] * g[k] * s;
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
    fn element_tangent(&self, t: f64, out: &mut Vec<Triplet<usize, usize, f64>>) {
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
}

/// The committed state of a model as checkpoints hold it, and its restoration.
impl FeModel {
    /// Accumulated spins of the committed configuration (checkpoints).
    pub fn committed_spins(&self) -> &[Vector3<f64>] {
        &self.committed.spin_sum
    }

    /// The explicit BT4 shells, if any (their state and output fields).
    pub fn bt4(&self) -> Option<&Bt4> {
        self.bt4.as_ref().map(|b| &b.shells)
    }

    /// Restores a committed state (configuration, accumulated spins, the material state of
    /// the elements as `element_state` reads it, concatenated, and the BT4 state) and commits
    /// it, so that a run resumes bitwise; refuses arrays of another model.
    pub fn restore_committed(
        &mut self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        spins: &[Vector3<f64>],
        material: &[f64],
        bt4: Option<crate::elements::bt4::Bt4State>,
    ) -> Result<(), String> {
        let nn = self.x0.len();
        if x.len() != nn || r.len() != nn || spins.len() != nn {
            return Err(format!("a configuration of another mesh ({} nodes, not {nn})", x.len()));
        }
        if material.len() != self.committed.material.len() {
            return Err(format!(
                "{} material state values, the model holds {}",
                material.len(),
                self.committed.material.len()
            ));
        }
        match (&mut self.bt4, bt4) {
            (Some(b), Some(s)) => {
                let have = b.shells.state();
                if (s.stress.len(), s.alpha.len(), s.hourglass.len())
                    != (have.stress.len(), have.alpha.len(), have.hourglass.len())
                {
                    return Err("a BT4 state of another mesh or thickness rule".into());
                }
                b.shells.set_state(s);
                b.evaluated = false;
            }
            (None, None) => {}
            (Some(_), None) => return Err("the model has BT4 shells, the state has none".into()),
            (None, Some(_)) => return Err("the state has BT4 shells, the model has none".into()),
        }
        let s = &mut self.trial;
        s.x.copy_from_slice(x);
        s.r.copy_from_slice(r);
        s.spin_sum.copy_from_slice(spins);
        s.material.copy_from_slice(material);
        self.committed.clone_from(&self.trial);
        self.fint_valid = false;
        Ok(())
    }
}
