//! `[structure]`: which structure participant runs, and the settings of `structure-solver`
//! (DESIGN §6).
//!
//! Settings of `structure-solver` are optional here (a case may couple `rigid-structure`
//! instead); `structure-solver` checks that what it needs is present when it runs.

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
}

impl StructureSection {
    /// The command that starts this participant.
    pub fn command(&self) -> Vec<String> {
        self.command.clone().unwrap_or_else(|| vec!["structure-solver".to_string()])
    }

    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        if let Some(r) = &self.rigid {
            r.validate()?;
        }
        Ok(())
    }
}
