//! `[fluid]`: which fluid participant runs, and the settings of `fluid-solver` (DESIGN §5).
//!
//! Settings of `fluid-solver` are optional here (a case may couple the analytic piston fluid
//! instead); `fluid-solver` checks that what it needs is present when it runs.

use super::PistonFluid;
use serde::Deserialize;

/// `[fluid]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidSection {
    /// Executable and arguments of the fluid participant; default `["fluid-solver"]`.
    #[serde(default)]
    pub command: Option<Vec<String>>,
    /// `[fluid.piston]`: the analytic acoustic-column fluid used by tests and fake-participant cases.
    #[serde(default)]
    pub piston: Option<PistonFluid>,
}

impl FluidSection {
    /// The command that starts this participant.
    pub fn command(&self) -> Vec<String> {
        self.command.clone().unwrap_or_else(|| vec!["fluid-solver".to_string()])
    }

    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        if let Some(p) = &self.piston {
            p.validate()?;
        }
        Ok(())
    }
}
