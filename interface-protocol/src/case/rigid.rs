//! `[structure.rigid]`: a rigid body on springs and dampers with 1 to 6 degrees of freedom and
//! optional prescribed motion, the model of `rigid-structure`.
//!
//! ```toml
//! [structure.rigid]
//! mass = 2.0
//! inertia = [0.1, 0.1, 0.2]      # principal moments about the reference point (rotations only)
//! dofs = ["x", "rz"]             # free among x y z rx ry rz; default ["x"]
//! stiffness = [1e4, 50.0]        # one value for every DOF, or one per DOF [N/m, N m/rad]
//! damping = 0.0
//! u0 = [0.01, 0.0]
//! v0 = 0.0
//! reference = [0.0, 0.0, 0.0]    # position of the reference point at rest
//! wet_nodes = [[0.0, -0.5, 0.0], [0.0, 0.5, 0.0]]   # relative to the reference point
//! wet_elements = []              # triangles / quads over wet_nodes (0-based)
//! probe = "piston"               # name of the body in structure_probes.csv
//! [[structure.rigid.prescribed]] # u(t) = amplitude (1 - cos 2π frequency t), loads ignored
//! dof = "x"
//! amplitude = 1e-3
//! frequency = 50.0
//! ```

use serde::Deserialize;

/// Names of the six rigid-body degrees of freedom, in order.
pub const RIGID_DOFS: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// One value for every DOF, or one per DOF.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum PerDof {
    All(f64),
    Each(Vec<f64>),
}

impl Default for PerDof {
    fn default() -> Self {
        PerDof::All(0.0)
    }
}

impl PerDof {
    /// The values for `n` DOFs, or what was expected.
    pub fn values(&self, n: usize) -> Result<Vec<f64>, String> {
        match self {
            PerDof::All(v) => Ok(vec![*v; n]),
            PerDof::Each(v) if v.len() == n => Ok(v.clone()),
            PerDof::Each(v) => Err(format!(
                "expected one number or {n} (one per entry of `dofs`), got {}",
                v.len()
            )),
        }
    }
}

/// `[[structure.rigid.prescribed]]`: u(t) = amplitude (1 - cos 2π frequency t) on one DOF.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PrescribedMotion {
    pub dof: String,
    pub amplitude: f64,
    pub frequency: f64,
}

impl PrescribedMotion {
    /// Displacement, velocity and acceleration at `t`.
    pub fn at(&self, t: f64) -> [f64; 3] {
        let w = 2.0 * std::f64::consts::PI * self.frequency;
        let a = self.amplitude;
        [a * (1.0 - (w * t).cos()), a * w * (w * t).sin(), a * w * w * (w * t).cos()]
    }
}

/// `[structure.rigid]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidBody {
    /// Mass m [kg].
    pub mass: f64,
    /// Principal moments of inertia about the reference point [kg m²] (body axes = x, y, z).
    #[serde(default)]
    pub inertia: [f64; 3],
    /// Free degrees of freedom, a subset of `RIGID_DOFS`.
    #[serde(default = "default_dofs")]
    pub dofs: Vec<String>,
    /// Spring stiffness k (restoring force -k u) per DOF.
    #[serde(default)]
    pub stiffness: PerDof,
    /// Damper coefficient c (force -c v) per DOF.
    #[serde(default)]
    pub damping: PerDof,
    /// Initial displacement and velocity per DOF.
    #[serde(default)]
    pub u0: PerDof,
    #[serde(default)]
    pub v0: PerDof,
    /// Reference point at rest [m].
    #[serde(default)]
    pub reference: [f64; 3],
    /// Wet-surface nodes relative to the reference point; default one node at it.
    #[serde(default = "default_wet_nodes")]
    pub wet_nodes: Vec<[f64; 3]>,
    /// Wet-surface triangles or quads (3 or 4 indices into `wet_nodes`).
    #[serde(default)]
    pub wet_elements: Vec<Vec<u32>>,
    /// Name of the body in `structure_probes.csv`.
    #[serde(default = "default_probe")]
    pub probe: String,
    /// DOFs whose motion is prescribed (their loads are ignored).
    #[serde(default)]
    pub prescribed: Vec<PrescribedMotion>,
}

fn default_dofs() -> Vec<String> {
    vec!["x".to_string()]
}
fn default_wet_nodes() -> Vec<[f64; 3]> {
    vec![[0.0; 3]]
}
fn default_probe() -> String {
    "body".to_string()
}

impl RigidBody {
    /// Indices (into `RIGID_DOFS`) of the free DOFs.
    pub fn dof_indices(&self) -> Vec<usize> {
        self.dofs.iter().filter_map(|d| RIGID_DOFS.iter().position(|n| n == d)).collect()
    }

    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        let f = |name: &str| format!("structure.rigid.{name}");
        super::require_positive(&f("mass"), self.mass)?;
        if self.dofs.is_empty() || self.dofs.len() > 6 {
            return Err((
                f("dofs"),
                "expected 1 to 6 of \"x\", \"y\", \"z\", \"rx\", \"ry\", \"rz\"".into(),
            ));
        }
        for (i, d) in self.dofs.iter().enumerate() {
            let Some(k) = RIGID_DOFS.iter().position(|n| n == d) else {
                return Err((
                    f("dofs"),
                    format!("unknown DOF \"{d}\": expected one of {RIGID_DOFS:?}"),
                ));
            };
            if self.dofs[..i].contains(d) {
                return Err((f("dofs"), format!("DOF \"{d}\" is listed twice")));
            }
            if k >= 3 && !(self.inertia[k - 3].is_finite() && self.inertia[k - 3] > 0.0) {
                return Err((
                    f("inertia"),
                    format!("DOF \"{d}\" is free: expected inertia[{}] > 0", k - 3),
                ));
            }
        }
        let n = self.dofs.len();
        for (name, v, nonneg) in [
            ("stiffness", &self.stiffness, true),
            ("damping", &self.damping, true),
            ("u0", &self.u0, false),
            ("v0", &self.v0, false),
        ] {
            let values = v.values(n).map_err(|m| (f(name), m))?;
            if values.iter().any(|x| !x.is_finite() || (nonneg && *x < 0.0)) {
                let what = if nonneg { "finite numbers >= 0" } else { "finite numbers" };
                return Err((f(name), format!("expected {what}, got {values:?}")));
            }
        }
        if self.wet_nodes.is_empty() || self.wet_nodes.iter().flatten().any(|x| !x.is_finite()) {
            return Err((
                f("wet_nodes"),
                "expected at least one node of three finite coordinates".into(),
            ));
        }
        for (i, e) in self.wet_elements.iter().enumerate() {
            if !(3..=4).contains(&e.len()) || e.iter().any(|&k| k as usize >= self.wet_nodes.len())
            {
                return Err((
                    f("wet_elements"),
                    format!(
                        "element {i}: expected 3 or 4 indices below {} (the number of wet_nodes), got {e:?}",
                        self.wet_nodes.len()
                    ),
                ));
            }
        }
        for p in &self.prescribed {
            if !self.dofs.contains(&p.dof) {
                return Err((
                    f("prescribed.dof"),
                    format!("\"{}\" is not among dofs {:?}", p.dof, self.dofs),
                ));
            }
            if !(p.amplitude.is_finite() && p.frequency.is_finite() && p.frequency >= 0.0) {
                return Err((
                    f("prescribed"),
                    "expected a finite amplitude and a frequency >= 0".into(),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::case::Case;
    use std::path::Path;

    fn parse(body: &str) -> Result<Case, String> {
        Case::parse(&format!("[structure.rigid]\n{body}"), Path::new("case.toml"), &[])
            .map_err(|e| e.to_string())
    }

    #[test]
    fn scalar_values_apply_to_every_dof() {
        let c = parse("mass = 1.0\nstiffness = 4.0\ndofs = [\"x\", \"y\"]").unwrap();
        let r = c.structure.unwrap().rigid.unwrap();
        assert_eq!(r.stiffness.values(2).unwrap(), [4.0, 4.0]);
        assert_eq!(r.dof_indices(), [0, 1]);
    }

    #[test]
    fn bad_rigid_sections_name_the_field() {
        for (body, field, says) in [
            ("mass = 1.0\ndofs = [\"q\"]", "structure.rigid.dofs", "unknown DOF"),
            ("mass = 1.0\ndofs = [\"rz\"]", "structure.rigid.inertia", "inertia[2] > 0"),
            ("mass = 1.0\nstiffness = [1.0, 2.0]", "structure.rigid.stiffness", "expected one number or 1"),
            ("mass = 1.0\nwet_elements = [[0, 1, 2]]", "structure.rigid.wet_elements", "below 1"),
            ("mass = 1.0\n[[structure.rigid.prescribed]]\ndof = \"y\"\namplitude = 1.0\nfrequency = 1.0", "structure.rigid.prescribed.dof", "not among"),
        ] {
            let e = parse(body).unwrap_err();
            assert!(e.contains(field) && e.contains(says), "{body}: {e}");
        }
    }
}
