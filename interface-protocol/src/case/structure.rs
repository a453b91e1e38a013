//! `[structure]`: which structure participant runs, and the model and analysis of
//! `structure-solver` (DESIGN §6).
//!
//! Settings of `structure-solver` are optional here (a case may couple `rigid-structure`
//! instead); `structure-solver` checks that what it needs is present when it runs, and the
//! checks that need the mesh (set names, cell kinds of a part) happen there, naming the field.
//!
//! ```toml
//! [structure]
//! # Mesh: one generator or a gmsh file (its physical groups become node and cell sets).
//! #   rectangle  lx, ly, nx, ny                      [0,lx]x[0,ly] in z = 0
//! #   cylinder   radius, length, n_theta, n_axial, theta_deg = [0, 360]   about z
//! #   sphere     radius, n_theta, n_phi, theta_deg = [0, 360], phi_deg = [0, 90]
//! #              (alias "hemisphere"; phi from +z; a pole becomes triangles)
//! #   annulus    r_inner, r_outer, n_theta, n_r, theta_deg = [0, 360]  in z = 0
//! #   line       from, to, n                         2-node beams
//! #   gmsh       file                                relative to the case file
//! #              coincident_nodes = "warn" | "allow"  nodes of one position that no element
//! #              shares (the mesh is not connected there): a warning naming them, or intended
//! #              (a notch)
//! # Grids have node sets u0, u1, v0, v1 (their edges; lines: start, end) and the cell set
//! # all; `triangles = true` splits quadrilaterals; coincident nodes (seams) are merged.
//! # Every mesh is refused with an inverted or zero-volume tet, a bow-tie or zero-area
//! # quadrilateral, a zero-area triangle or a zero-length line (named by cell or element tag).
//! mesh = { generator = "rectangle", lx = 1.0, ly = 0.1, nx = 24, ny = 2 }
//!
//! # Analysis: central_difference (default) | newmark | midpoint | static.
//! integrator = "central_difference"
//! dt = 1e-6                         # central differences: default safety x critical step
//! safety = 0.8
//! t_end = 0.1                       # static: the final load factor (default 1)
//! output_every = 100                # steps between probe rows
//! # static only: steps (load increments, default 10), Newton settings and displacement
//! # control of one dof (the loads then scale with the load factor λ):
//! # steps = 10
//! # newton = { tol = 1e-6, max_iter = 30, max_cuts = 8 }
//! # control = { point = [1.0, 0.0, 0.0], dof = "uz", value = 0.5 }   # or set = "tip"
//! # or arc-length path following (Crisfield) until the load factor reaches t_end, at most
//! # `steps` steps; `initial` arc length (norm of a step's free-dof increment), its bounds
//! # `min`/`max` (default initial/1000, 10 initial) and the Newton iterations it aims at:
//! # arc_length = { initial = 0.1, min = 1e-4, max = 1.0, desired_iterations = 4 }
//! wet_set = "wet"                   # node or cell set sent to the fluid when coupled
//!
//! # Materials by name: elastic, or J2 with linear isotropic hardening when sigma_y is given
//! # (hardening = plastic modulus H, σ = σy + H εp). `material = {...}` is the one material
//! # named "default".
//! [structure.materials.steel]
//! e = 200e9
//! nu = 0.3
//! rho = 7800.0
//! sigma_y = 250e6
//! hardening = 1e9
//!
//! # Parts: an element per cell set (a node set means the cells whose nodes all lie in it;
//! # default every cell of the mesh's highest dimension: cells of a lower one in no part, as
//! # the boundary lines of a gmsh surface, only define sets). Without parts, one part of
//! # `element` (default bt4), `material` and `thickness` covers the mesh.
//! #   bt4    explicit one-point shell: BT4 on quadrilaterals, BLT3 on triangles (the cell
//! #          decides, so a triangle or mixed mesh runs as one explicit part); any number of
//! #          materials; J2 bt4 parts share one `points`, elastic ones take it
//! #   mitc4  shell, quadrilaterals      dkt   shell, triangles
//! #   shell  mitc4 or dkt by cell kind  beam  2-node beam      tet4  solid
//! # J2 shells integrate `points` Gauss points through the thickness (default 5).
//! [[structure.parts]]
//! set = "all"
//! element = "bt4"
//! material = "steel"
//! thickness = 0.01
//! points = 5
//! # beams: section = { rectangle = [b, h] } or { area, iy, iz, j }, and `up`, the local y axis
//!
//! # Node sets by box (min and max corners), beside the mesh's.
//! [structure.sets]
//! clamp = { min = [-1e-9, -1, -1], max = [1e-9, 1, 1] }
//! tip = { min = [0.999999, -1, -1], max = [1.000001, 1, 1] }
//!
//! # Boundary conditions: one of fixed, symmetry, prescribed per entry.
//! [[structure.bc]]
//! set = "clamp"
//! fixed = ["ux", "uy", "uz", "rx", "ry", "rz"]
//! # symmetry = "y"                  # plane normal to y: uy = rx = rz = 0
//! # symmetry = [0.5, 0.866, 0]      # any normal: u·n = 0, rotation only about n
//! # prescribed = { dof = "uz", value = 0.01, curve = "linear" }   # value x curve(t)
//!
//! # Curves of time (the load factor in static runs): "constant", "linear" (= t),
//! # { ramp = T } (0 to 1 over [0, T], then 1), { table = [[t, value], ...] } (linear between
//! # points, constant outside). Default: "linear" in static runs, "constant" in dynamic ones.
//! [[structure.loads]]               # point load per node of a node set (force or moment)
//! set = "tip"
//! dof = "uz"
//! value = 10.0
//! curve = { ramp = 1e-3 }
//! # pressure = 1e5, set = "all"     # follower pressure on shell cells, along the normal of
//! #                                 # the cells' node order; on a set of tets, of faces in
//! #                                 # no part or of nodes of a solid: on the solid's boundary
//! #                                 # faces there, pushing into it
//! # gravity = [0.0, 0.0, -9.81]     # acceleration on the lumped mass
//!
//! [[structure.initial_velocity]]
//! set = "all"
//! dof = "uz"
//! value = 1.0
//!
//! [[structure.probes]]              # displacement and velocity of the nearest node, to
//! name = "tip"                      # structure_probes.csv (static: time = load factor)
//! point = [1.0, 0.0, 0.0]
//!
//! # Rigid bodies: the nodes of `set` move with a new reference node (node set
//! # "<set>_reference", where BCs and loads of the body go; loads on the set reach it too):
//! # [[structure.rigid_bodies]]
//! # set = "hub"
//! # reference = [0.0, 0.0, 0.0]     # default: the mass centre of the set
//! # reference_set = "hub_centre"    # or an existing node (a set of one node) as reference
//! # mass = 1.0                      # mass added at the reference node
//! # inertia = [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.2]]  # rotary inertia added
//! #                                 # about the reference node (global axes, symmetric)
//! # spring = { stiffness = [1400.0, 0.0, 0.0], preload = [-1000.0, 0.0, 0.0] }
//! #   a linear spring on the reference node's translations, in the global axes: the force
//! #   on it is `preload - stiffness · u` per axis (`u` its displacement from the start; N/m,
//! #   N), part of the internal force and the tangent, its `2 sqrt(m/k)` in the stable step
//! ```

use std::collections::BTreeMap;

use super::RigidBody;

mod rigid_part;
mod solution;
mod validate;
pub use rigid_part::{RigidPart, RigidSpring};
use serde::Deserialize;
pub use solution::{ArcLengthSection, ControlSection, Integrator, NewtonSection};

/// `[structure]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureSection {
    /// Executable and arguments of the structure participant; default `["structure-solver"]`.
    #[serde(default)]
    pub command: Option<Vec<String>>,
    /// `[structure.rigid]`: the rigid body of `rigid-structure`.
    #[serde(default)]
    pub rigid: Option<RigidBody>,
    /// Mesh of `structure-solver`: a generator or a gmsh file.
    #[serde(default)]
    pub mesh: Option<StructureMesh>,
    /// The material named `"default"`.
    #[serde(default)]
    pub material: Option<StructureMaterial>,
    /// `[structure.materials.NAME]`.
    #[serde(default)]
    pub materials: BTreeMap<String, StructureMaterial>,
    /// Shell thickness of the part made without `[[structure.parts]]`.
    #[serde(default)]
    pub thickness: Option<f64>,
    /// Element of the part made without `[[structure.parts]]`; default `bt4`.
    #[serde(default)]
    pub element: Option<ElementType>,
    #[serde(default)]
    pub parts: Vec<StructurePart>,
    /// Default `central_difference`.
    #[serde(default)]
    pub integrator: Option<Integrator>,
    /// Time step; central differences default to `safety` x the critical step, recomputed
    /// every step from the element bound at the current configuration.
    #[serde(default)]
    pub dt: Option<f64>,
    /// Fraction of the critical step; default 0.8.
    #[serde(default)]
    pub safety: Option<f64>,
    /// Coupled, central differences: substeps per coupling step (default: the least that keeps
    /// each within the stable step, recomputed every coupling step).
    #[serde(default)]
    pub substeps: Option<u32>,
    /// End time of a run alone (static: the final load factor, default 1).
    #[serde(default)]
    pub t_end: Option<f64>,
    /// Static: load increments; default 10.
    #[serde(default)]
    pub steps: Option<usize>,
    /// Static: Newton settings.
    #[serde(default)]
    pub newton: Option<NewtonSection>,
    /// Static: displacement control.
    #[serde(default)]
    pub control: Option<ControlSection>,
    /// Static: arc-length path following.
    #[serde(default)]
    pub arc_length: Option<ArcLengthSection>,
    /// Steps between probe rows; default 1.
    #[serde(default)]
    pub output_every: Option<u64>,
    /// Node or cell set of the wet surface.
    #[serde(default)]
    pub wet_set: Option<String>,
    /// Node sets by box.
    #[serde(default)]
    pub sets: BTreeMap<String, BoxSet>,
    #[serde(default)]
    pub bc: Vec<StructureBc>,
    #[serde(default)]
    pub loads: Vec<StructureLoad>,
    #[serde(default)]
    pub initial_velocity: Vec<NodalValue>,
    #[serde(default)]
    pub probes: Vec<StructureProbe>,
    /// `[[structure.rigid_bodies]]`.
    #[serde(default)]
    pub rigid_bodies: Vec<RigidPart>,
}

/// `mesh = { generator = "...", ... }`; angles in degrees.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(
    tag = "generator",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "a mesh table with a `generator` key, e.g. { generator = \"gmsh\", file = \"plate.msh\" }"
)]
pub enum StructureMesh {
    Rectangle {
        lx: f64,
        ly: f64,
        nx: usize,
        ny: usize,
        #[serde(default)]
        triangles: bool,
    },
    Cylinder {
        radius: f64,
        length: f64,
        n_theta: usize,
        n_axial: usize,
        #[serde(default = "full_turn")]
        theta_deg: [f64; 2],
        #[serde(default)]
        triangles: bool,
    },
    #[serde(alias = "hemisphere")]
    Sphere {
        radius: f64,
        n_theta: usize,
        n_phi: usize,
        #[serde(default = "full_turn")]
        theta_deg: [f64; 2],
        #[serde(default = "upper_half")]
        phi_deg: [f64; 2],
        #[serde(default)]
        triangles: bool,
    },
    Annulus {
        r_inner: f64,
        r_outer: f64,
        n_theta: usize,
        n_r: usize,
        #[serde(default = "full_turn")]
        theta_deg: [f64; 2],
        #[serde(default)]
        triangles: bool,
    },
    Line {
        from: [f64; 3],
        to: [f64; 3],
        n: usize,
    },
    Gmsh {
        file: String,
        /// Nodes of one position that no element shares: a warning by default.
        #[serde(default)]
        coincident_nodes: CoincidentNodes,
    },
}

/// `coincident_nodes` of a gmsh mesh: what to do with distinct nodes at one position that no
/// element shares (the mesh is not connected there).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoincidentNodes {
    /// A warning naming them (two surfaces meshed apart by mistake).
    #[default]
    Warn,
    /// They are intended (a notch, a crack): no warning.
    Allow,
}

fn full_turn() -> [f64; 2] {
    [0.0, 360.0]
}

fn upper_half() -> [f64; 2] {
    [0.0, 90.0]
}

/// Linear elastic, or J2 with linear isotropic hardening when `sigma_y` is given; `hardening`
/// is the plastic modulus `H` (`σ = σy + H εp`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureMaterial {
    pub e: f64,
    pub nu: f64,
    pub rho: f64,
    #[serde(default)]
    pub sigma_y: Option<f64>,
    #[serde(default)]
    pub hardening: f64,
}

/// Element families of a part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ElementType {
    /// Explicit one-point shell: Belytschko-Tsay on quadrilaterals, BLT3 on triangles.
    Bt4,
    /// MITC4 shell on quadrilaterals.
    Mitc4,
    /// DKT shell on triangles.
    Dkt,
    /// MITC4 on quadrilaterals, DKT on triangles.
    Shell,
    Beam,
    Tet4,
}

/// `[[structure.parts]]`: what the cells of a set become.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructurePart {
    /// Cell set, or node set (the cells whose nodes all lie in it); default every cell of the
    /// mesh's highest dimension.
    #[serde(default)]
    pub set: Option<String>,
    pub element: ElementType,
    /// Name in `materials` (`"default"` is `material`); default the only material.
    #[serde(default)]
    pub material: Option<String>,
    /// Shell thickness.
    #[serde(default)]
    pub thickness: Option<f64>,
    /// Gauss points through the thickness of J2 shells; default 5.
    #[serde(default)]
    pub points: Option<usize>,
    /// Beam cross-section.
    #[serde(default)]
    pub section: Option<BeamSectionSpec>,
    /// Beams: the local `y` axis (projected normal to the beam).
    #[serde(default)]
    pub up: Option<[f64; 3]>,
}

/// `section = { rectangle = [b, h] }` (b along the local y axis) or `{ area, iy, iz, j }`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeamSectionSpec {
    #[serde(default)]
    pub rectangle: Option<[f64; 2]>,
    #[serde(default)]
    pub area: Option<f64>,
    #[serde(default)]
    pub iy: Option<f64>,
    #[serde(default)]
    pub iz: Option<f64>,
    #[serde(default)]
    pub j: Option<f64>,
}

/// Nodes inside an axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSet {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// The six nodal dofs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Dof {
    Ux,
    Uy,
    Uz,
    Rx,
    Ry,
    Rz,
}

impl Dof {
    /// Index in `[ux, uy, uz, rx, ry, rz]`.
    pub fn index(self) -> usize {
        self as usize
    }
}

/// A global axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    pub fn index(self) -> usize {
        self as usize
    }
}

/// `symmetry`: a plane normal to a global axis, or to any (non-zero) vector.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged, expecting = "a symmetry plane: \"x\", \"y\", \"z\" or a normal [nx, ny, nz]")]
pub enum Symmetry {
    Axis(Axis),
    Normal([f64; 3]),
}

/// A scalar function of time (the load factor in static runs).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(
    untagged,
    expecting = "a curve: \"constant\", \"linear\", { ramp = T } or { table = [[t, value], ...] }"
)]
pub enum CurveSpec {
    Named(CurveName),
    Ramp(RampCurve),
    Table(TableCurve),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveName {
    Constant,
    Linear,
}

/// 0 at `t = 0` to 1 at `t = ramp`, then 1.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RampCurve {
    pub ramp: f64,
}

/// Piecewise linear through `(t, value)` points, constant outside.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableCurve {
    pub table: Vec<[f64; 2]>,
}

/// `[[structure.bc]]`: one of `fixed`, `symmetry`, `prescribed` on the nodes of `set`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureBc {
    pub set: String,
    /// Dofs held at zero.
    #[serde(default)]
    pub fixed: Vec<Dof>,
    /// Symmetry about the plane normal to this axis or vector.
    #[serde(default)]
    pub symmetry: Option<Symmetry>,
    #[serde(default)]
    pub prescribed: Option<Prescribed>,
}

/// `prescribed = { dof, value, curve }`: the dof's displacement (rotation) is `value · curve(t)`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Prescribed {
    pub dof: Dof,
    pub value: f64,
    #[serde(default)]
    pub curve: Option<CurveSpec>,
}

/// `[[structure.loads]]`: a point load (`set`, `dof`, `value`: per node), a follower
/// `pressure` on the shell cells of `set` (default all), or `gravity`; each times `curve`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureLoad {
    #[serde(default)]
    pub set: Option<String>,
    #[serde(default)]
    pub dof: Option<Dof>,
    #[serde(default)]
    pub value: Option<f64>,
    #[serde(default)]
    pub pressure: Option<f64>,
    #[serde(default)]
    pub gravity: Option<[f64; 3]>,
    #[serde(default)]
    pub curve: Option<CurveSpec>,
}

/// What a `[[structure.loads]]` entry is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LoadKind<'a> {
    Point { set: &'a str, dof: Dof, value: f64 },
    Pressure { set: Option<&'a str>, p: f64 },
    Gravity([f64; 3]),
}

impl StructureLoad {
    /// The load this entry describes (after validation).
    pub fn kind(&self) -> Option<LoadKind<'_>> {
        match (self.value, self.pressure, self.gravity) {
            (Some(value), None, None) => {
                Some(LoadKind::Point { set: self.set.as_deref()?, dof: self.dof?, value })
            }
            (None, Some(p), None) => Some(LoadKind::Pressure { set: self.set.as_deref(), p }),
            (None, None, Some(g)) => Some(LoadKind::Gravity(g)),
            _ => None,
        }
    }
}

/// A value on one dof of every node of a set.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodalValue {
    pub set: String,
    pub dof: Dof,
    pub value: f64,
}

/// A probe at the node nearest to `point`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureProbe {
    pub name: String,
    pub point: [f64; 3],
}

impl StructureSection {
    /// The command that starts this participant.
    pub fn command(&self) -> Vec<String> {
        self.command.clone().unwrap_or_else(|| vec!["structure-solver".to_string()])
    }

    /// The materials by name, `material` as `"default"`.
    pub fn all_materials(&self) -> BTreeMap<String, StructureMaterial> {
        let mut m = self.materials.clone();
        if let Some(d) = self.material {
            m.insert("default".into(), d);
        }
        m
    }

    /// The integrator; default central differences.
    pub fn integrator(&self) -> Integrator {
        self.integrator.unwrap_or(Integrator::CentralDifference)
    }
}
