//! `FeModel`: an assembled finite-element structure implementing `Model` (DESIGN §6).
//!
//! Files by job: `build` (mesh cells to elements, lumped mass), `constraints` (fixed,
//! prescribed and skew-symmetry dofs and their reduction), `rigid_bodies` (rigid bodies and
//! links: slaves on masters, the reduction `Tᵀ f`, `Tᵀ K T`), `springs` (linear springs on a
//! node's translations with a preload: a rigid body's spring), `loads` (time curves, point
//! loads, pressure, gravity, the coupling's nodal array), `forces` (the `Model` the
//! integrators call; `element_forces` its element loop, `explicit_shells` the BT4 and BLT3
//! shells), `stable_step` (the element bound of the critical step at the current
//! configuration), `state` (the committed state checkpoints hold).
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
//! Topology (`topology`: user ids apart from slots, the version; `topology_change`: nodes
//! added and elements duplicated with their state at run time; `topology_record`: what a
//! checkpoint holds of it, and the rebuild of a changed model at a restart).
//!
//! Parts: elastic shells, J2 shells integrated through the thickness (MITC4, DKT), beams,
//! tets, and the explicit-only one-point shells (`explicit_shells`: BT4 on quadrilaterals,
//! BLT3 on triangles, any number of materials), which have no tangent (static and implicit
//! solvers return an error for a model holding them).

mod build;
mod constraints;
mod element_forces;
mod explicit_shells;
mod forces;
mod loads;
mod rigid_bodies;
mod springs;
mod stable_step;
mod state;
mod topology;
mod topology_change;
mod topology_record;

use nalgebra::{Matrix3, Vector3};

use crate::elements::blt3::Blt3;
use crate::elements::bt4::Bt4;
pub use crate::elements::RotaryInertia;
use crate::elements::{BeamSection, BeamYield, Element, ShellSection, ShellYield};
use crate::material::Material;
use crate::mesh::CellKind;
use crate::rigid::RigidBody;

use constraints::SkewNode;
use explicit_shells::ExplicitShells;
pub use loads::Curve;
pub use springs::{NodeSpring, SpringError};
pub use topology::{IdMap, Store, Topology, TopologyError};
pub use topology_change::NewNode;
pub use topology_record::TopologyRecord;

/// What a mesh cell becomes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Part {
    Shell(ShellSection),
    /// A shell of a J2 material integrated through the thickness (MITC4 or DKT).
    ShellJ2(ShellSection, ShellYield),
    /// A one-point explicit shell, elastic or J2 at the thickness points of the yield: the
    /// Belytschko-Tsay quadrilateral (`elements::bt4`) on a quadrilateral, the BLT3 triangle
    /// (`elements::blt3`) on a triangle. Explicit only, it has no tangent, so static and
    /// implicit solves refuse a model holding one. Parts may differ in material; the J2 ones
    /// share one number of thickness points, which the elastic ones take (5 when all are
    /// elastic; a Gauss rule of two or more points integrates an elastic section exactly).
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
    #[error(
        "cell {cell}: a J2 explicit shell of {points} thickness points, where those of cell \
         {first} have {first_points}; J2 bt4 parts share one number of points"
    )]
    ShellPoints { cell: usize, points: usize, first: usize, first_points: usize },
    #[error("cell {cell}: more than {max} explicit shell materials", max = u16::MAX as usize + 1)]
    ShellMaterials { cell: usize },
    #[error("cell {cell}: shell thickness {h}, expected a positive finite value")]
    ShellThickness { cell: usize, h: f64 },
    #[error("symmetry plane: the normal {normal:?} is not a finite non-zero vector")]
    BadNormal { normal: [f64; 3] },
    #[error("symmetry plane: node {node} belongs to a rigid body")]
    SymmetryRigid { node: usize },
    #[error("symmetry plane: node {node} has a prescribed dof")]
    SymmetryPrescribed { node: usize },
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
    /// The explicit-only one-point shells, if any.
    explicit: Option<ExplicitShells>,
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
    /// Linear springs on nodes (`springs`).
    springs: Vec<springs::NodeSpring>,
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
    /// Pressures on boundary faces of solids (outward counter-clockwise triangles).
    face_pressures: Vec<(Vec<[usize; 3]>, f64, Curve)>,
    gravity: Option<([f64; 3], Curve)>,
    external: Vec<f64>,
    /// The nodal load from outside the model given with the last external force
    /// (`Model::external_force_with`; empty: none), reduced with the model's own loads.
    held_extra: Vec<f64>,
    /// Work arrays of the element force loop.
    scratch: Vec<element_forces::ElementScratch>,
    /// Each element's bound of the critical step at the reference configuration.
    element_bound: Vec<stable_step::ElementBound>,
    /// User ids of nodes and cells, where each cell's element is stored, the version.
    topology: topology::Topology,
}

fn gather<T: Copy>(all: &[T], nodes: &[usize]) -> Vec<T> {
    nodes.iter().map(|&n| all[n]).collect()
}

impl FeModel {
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

    /// The rigid bodies, in the order they were made.
    pub fn rigid_bodies(&self) -> &[RigidBody] {
        &self.rigid
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

    /// Accumulated spins of the committed configuration (checkpoints).
    pub fn committed_spins(&self) -> &[Vector3<f64>] {
        &self.committed.spin_sum
    }

    /// The explicit BT4 shells (the quadrilaterals of `Part::Bt4`), if any (their state and
    /// output fields).
    pub fn bt4(&self) -> Option<&Bt4> {
        self.explicit.as_ref().and_then(|b| b.quads.as_ref())
    }

    /// The explicit BLT3 shells (the triangles of `Part::Bt4`), if any.
    pub fn blt3(&self) -> Option<&Blt3> {
        self.explicit.as_ref().and_then(|b| b.triangles.as_ref())
    }
}
