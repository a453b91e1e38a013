//! `[[structure.rigid_bodies]]`: a rigid part of `structure-solver` and the linear spring that
//! may hold its reference node.

use serde::Deserialize;

/// `[[structure.rigid_bodies]]`: the nodes of `set` move as one rigid body with a new
/// reference node at `reference` (default their mass centre), or the existing node of the
/// one-node set `reference_set`, which carries `mass` and the rotary inertia `inertia`
/// (about it, global axes) more, and the `spring`, if any.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidPart {
    pub set: String,
    #[serde(default)]
    pub reference: Option<[f64; 3]>,
    #[serde(default)]
    pub reference_set: Option<String>,
    #[serde(default)]
    pub mass: f64,
    #[serde(default)]
    pub inertia: Option<[[f64; 3]; 3]>,
    #[serde(default)]
    pub spring: Option<RigidSpring>,
}

/// `spring = { stiffness = [kx, ky, kz], preload = [Fx, Fy, Fz] }`: a linear spring on the
/// translations of the body's reference node, in the global axes. The force it puts on the
/// node is `preload - K u` (`K = diag(stiffness)` in N/m, `u` the node's displacement from
/// its start, `preload` in N: the spring's force at the start), so a preload that balances
/// a steady load starts the body in equilibrium.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidSpring {
    pub stiffness: [f64; 3],
    #[serde(default)]
    pub preload: [f64; 3],
}

impl RigidSpring {
    /// Finite stiffness `>= 0` with one positive, a finite preload; errors name `field`'s
    /// keys.
    pub(crate) fn validate(&self, field: &str) -> Result<(), (String, String)> {
        let k = self.stiffness;
        if let Some(i) = (0..3).find(|&i| !(k[i].is_finite() && k[i] >= 0.0)) {
            return Err((
                format!("{field}.stiffness[{i}]"),
                format!("expected a finite stiffness >= 0 (N/m), got {}", k[i]),
            ));
        }
        if k.iter().all(|&k| k == 0.0) {
            return Err((
                format!("{field}.stiffness"),
                "expected a positive stiffness on at least one axis, got [0, 0, 0]".into(),
            ));
        }
        if let Some(i) = (0..3).find(|&i| !self.preload[i].is_finite()) {
            return Err((
                format!("{field}.preload[{i}]"),
                format!("expected a finite force (N), got {}", self.preload[i]),
            ));
        }
        Ok(())
    }
}
