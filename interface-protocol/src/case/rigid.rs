//! `[structure.rigid]`: a rigid body on springs and dampers, with optional prescribed motion, the
//! model of `rigid-structure`.

use serde::Deserialize;

/// `[structure.rigid]`: translation along one axis so far (the wet face moves rigidly).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidBody {
    /// Mass m [kg].
    pub mass: f64,
    /// Spring stiffness k [N/m] (restoring force -k u).
    #[serde(default)]
    pub stiffness: f64,
    /// Damper coefficient c [N s/m] (force -c v).
    #[serde(default)]
    pub damping: f64,
    /// Initial displacement and velocity along the axis.
    #[serde(default)]
    pub u0: f64,
    #[serde(default)]
    pub v0: f64,
}

impl RigidBody {
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        super::require_positive("structure.rigid.mass", self.mass)?;
        if !(self.stiffness >= 0.0 && self.stiffness.is_finite()) {
            return Err((
                "structure.rigid.stiffness".into(),
                format!("expected >= 0, got {}", self.stiffness),
            ));
        }
        if !(self.damping >= 0.0 && self.damping.is_finite()) {
            return Err((
                "structure.rigid.damping".into(),
                format!("expected >= 0, got {}", self.damping),
            ));
        }
        Ok(())
    }
}
