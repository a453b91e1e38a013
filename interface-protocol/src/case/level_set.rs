//! `[fluid.level_set]`: a moving interface between two fluids (thesis §3.3.2, DESIGN §5).
//!
//! With this section the interface between the case's two named fluids is carried by a level set
//! `φ` advected with the flow; the sign of `φ` gives each node's fluid (the initial background's
//! fluid where `φ < 0`, the other where `φ >= 0`), and `φ` is reset to a signed distance every
//! `reinit_every` steps. Without it, the initial material layout stays fixed.
//!
//! ```toml
//! [fluid.level_set]
//! reinit_every = 10   # steps between reinitialisations to a signed distance (0: never)
//! ```

use super::FluidMaterial;
use serde::Deserialize;

/// Largest `reinit_every` (a larger value is surely a typo: reinitialising never is `0`).
pub const MAX_REINIT_EVERY: u64 = 1_000_000;

/// `[fluid.level_set]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidLevelSet {
    /// Steps between reinitialisations of `φ` to a signed distance (0: never).
    #[serde(default = "ten")]
    pub reinit_every: u64,
}

fn ten() -> u64 {
    10
}

impl Default for FluidLevelSet {
    fn default() -> Self {
        FluidLevelSet { reinit_every: ten() }
    }
}

impl FluidLevelSet {
    /// The level set needs exactly two fluids (an embedded surface may sit among them).
    pub(crate) fn validate(&self, fluids: &[FluidMaterial<'_>]) -> Result<(), (String, String)> {
        if fluids.len() != 2 {
            let names: Vec<&str> = fluids.iter().map(|m| m.name).collect();
            return Err((
                "fluid.level_set".into(),
                format!(
                    "a level set separates exactly two fluids; the case has {} ({}): give two \
                     [fluid.fluids.<name>] tables",
                    fluids.len(),
                    names.join(", ")
                ),
            ));
        }
        if self.reinit_every > MAX_REINIT_EVERY {
            return Err((
                "fluid.level_set.reinit_every".into(),
                format!(
                    "expected at most {MAX_REINIT_EVERY} steps (0 never reinitialises), got {}",
                    self.reinit_every
                ),
            ));
        }
        Ok(())
    }
}
