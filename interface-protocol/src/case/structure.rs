//! `[structure]`: which structure participant runs, and the settings of `structure-solver`
//! (DESIGN §6).
//!
//! Settings of `structure-solver` are optional here (a case may couple `rigid-structure`
//! instead); `structure-solver` checks that what it needs is present when it runs.
//!
//! ```toml
//! [structure]
//! mesh = { generator = "rectangle", lx = 1.0, ly = 0.1, nx = 24, ny = 2 }   # or { gmsh = "plate.msh" }
//! material = { e = 200e9, nu = 0.3, rho = 7800.0, sigma_y = 250e6, hardening = 1e9 }
//! thickness = 0.01
//! element = "bt4"                 # bt4 (explicit) | mitc4 (implicit)
//! integrator = "central_difference"   # | newmark | midpoint
//! dt = 1e-6                       # optional for central differences: safety x critical step
//! safety = 0.8
//! t_end = 0.1
//! output_every = 100              # steps between probe rows
//! wet_set = "wet"                 # node set sent to the fluid when coupled
//! [structure.sets]                # node sets by box (min and max corners), beside the mesh's
//! clamp = { min = [-1e-9, -1, -1], max = [1e-9, 1, 1] }
//! [[structure.bc]]
//! set = "clamp"
//! dofs = ["ux", "uy", "uz", "rx", "ry", "rz"]
//! velocity = 0.0                  # prescribed velocity of those dofs (0 = fixed)
//! [[structure.loads]]
//! set = "tip"
//! dof = "uz"
//! value = 10.0                    # force (moment) per node
//! [[structure.initial_velocity]]
//! set = "all"
//! dof = "uz"
//! value = 1.0
//! [[structure.probes]]
//! name = "tip"
//! point = [1.0, 0.0, 0.0]         # the nearest node
//! ```

use super::RigidBody;
use serde::Deserialize;

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
    #[serde(default)]
    pub material: Option<StructureMaterial>,
    /// Shell thickness.
    #[serde(default)]
    pub thickness: Option<f64>,
    /// `"bt4"` (default) or `"mitc4"`.
    #[serde(default)]
    pub element: Option<String>,
    /// `"central_difference"` (default), `"newmark"` or `"midpoint"`.
    #[serde(default)]
    pub integrator: Option<String>,
    /// Time step; central differences default to `safety` x the critical step.
    #[serde(default)]
    pub dt: Option<f64>,
    /// Fraction of the critical step; default 0.8.
    #[serde(default)]
    pub safety: Option<f64>,
    /// End time of a run alone.
    #[serde(default)]
    pub t_end: Option<f64>,
    /// Steps between probe rows; default 1.
    #[serde(default)]
    pub output_every: Option<u64>,
    /// Node set of the wet surface.
    #[serde(default)]
    pub wet_set: Option<String>,
    /// Node sets by box.
    #[serde(default)]
    pub sets: std::collections::BTreeMap<String, BoxSet>,
    #[serde(default)]
    pub bc: Vec<StructureBc>,
    #[serde(default)]
    pub loads: Vec<NodalValue>,
    #[serde(default)]
    pub initial_velocity: Vec<NodalValue>,
    #[serde(default)]
    pub probes: Vec<StructureProbe>,
}

/// `mesh = { generator = "rectangle", ... }` or `mesh = { gmsh = "file.msh" }`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub enum StructureMesh {
    Rectangle { generator: String, lx: f64, ly: f64, nx: usize, ny: usize },
    Gmsh { gmsh: String },
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

/// Nodes inside an axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSet {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

/// Dofs of a set fixed or moving at a constant velocity.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureBc {
    pub set: String,
    pub dofs: Vec<String>,
    #[serde(default)]
    pub velocity: f64,
}

/// A value on one dof of every node of a set.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodalValue {
    pub set: String,
    pub dof: String,
    pub value: f64,
}

/// A probe at the node nearest to `point`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StructureProbe {
    pub name: String,
    pub point: [f64; 3],
}

/// Names of the six nodal dofs, in order.
pub const STRUCTURE_DOFS: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];

/// Index of a dof name.
pub fn structure_dof(name: &str) -> Option<usize> {
    STRUCTURE_DOFS.iter().position(|d| *d == name)
}

impl StructureSection {
    /// The command that starts this participant.
    pub fn command(&self) -> Vec<String> {
        self.command.clone().unwrap_or_else(|| vec!["structure-solver".to_string()])
    }

    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        use super::require_positive;
        if let Some(r) = &self.rigid {
            r.validate()?;
        }
        if let Some(StructureMesh::Rectangle { generator, lx, ly, nx, ny }) = &self.mesh {
            if generator != "rectangle" {
                return Err((
                    "structure.mesh.generator".into(),
                    format!("expected \"rectangle\", got \"{generator}\""),
                ));
            }
            require_positive("structure.mesh.lx", *lx)?;
            require_positive("structure.mesh.ly", *ly)?;
            if *nx == 0 || *ny == 0 {
                return Err((
                    "structure.mesh.nx".into(),
                    "expected at least one element each way".into(),
                ));
            }
        }
        if let Some(m) = &self.material {
            require_positive("structure.material.e", m.e)?;
            require_positive("structure.material.rho", m.rho)?;
            if !(m.nu > -1.0 && m.nu < 0.5) {
                return Err((
                    "structure.material.nu".into(),
                    format!("expected -1 < nu < 0.5, got {}", m.nu),
                ));
            }
            if let Some(sy) = m.sigma_y {
                require_positive("structure.material.sigma_y", sy)?;
            }
            if !(m.hardening >= 0.0 && m.hardening.is_finite()) {
                return Err((
                    "structure.material.hardening".into(),
                    format!("expected a finite number >= 0, got {}", m.hardening),
                ));
            }
        }
        for (field, v) in [
            ("structure.thickness", self.thickness),
            ("structure.dt", self.dt),
            ("structure.t_end", self.t_end),
        ] {
            if let Some(v) = v {
                require_positive(field, v)?;
            }
        }
        if let Some(s) = self.safety {
            if !(s > 0.0 && s <= 1.0) {
                return Err((
                    "structure.safety".into(),
                    format!("expected 0 < safety <= 1, got {s}"),
                ));
            }
        }
        if let Some(e) = &self.element {
            if e != "bt4" && e != "mitc4" {
                return Err((
                    "structure.element".into(),
                    format!("expected \"bt4\" or \"mitc4\", got \"{e}\""),
                ));
            }
        }
        if let Some(i) = &self.integrator {
            if !["central_difference", "newmark", "midpoint"].contains(&i.as_str()) {
                return Err((
                    "structure.integrator".into(),
                    format!(
                        "expected \"central_difference\", \"newmark\" or \"midpoint\", got \"{i}\""
                    ),
                ));
            }
        }
        let dof_ok = |field: &str, d: &str| {
            structure_dof(d).map(|_| ()).ok_or_else(|| {
                (field.to_string(), format!("expected one of {STRUCTURE_DOFS:?}, got \"{d}\""))
            })
        };
        for b in &self.bc {
            for d in &b.dofs {
                dof_ok("structure.bc.dofs", d)?;
            }
        }
        for l in &self.loads {
            dof_ok("structure.loads.dof", &l.dof)?;
        }
        for l in &self.initial_velocity {
            dof_ok("structure.initial_velocity.dof", &l.dof)?;
        }
        Ok(())
    }
}
