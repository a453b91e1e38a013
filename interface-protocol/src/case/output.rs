//! `[output]`: where and how often the solvers write.

use serde::Deserialize;

/// `[output]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    /// Output folder; `fsi run --out` and the solvers' `--out` take precedence. Default:
    /// `runs/<case>-<timestamp>`.
    #[serde(default)]
    pub dir: Option<String>,
    /// Write fields every this many solver steps (0: only the final state).
    #[serde(default)]
    pub fields_every: u64,
    /// Write a checkpoint every this many coupling steps (0: only at the end).
    #[serde(default)]
    pub checkpoint_every: u64,
    /// Write probes every this many solver steps.
    #[serde(default = "one")]
    pub probes_every: u64,
}

fn one() -> u64 {
    1
}

impl Default for OutputSection {
    fn default() -> Self {
        Self { dir: None, fields_every: 0, checkpoint_every: 0, probes_every: 1 }
    }
}

impl OutputSection {
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        if self.probes_every == 0 {
            return Err(("output.probes_every".into(), "expected an integer >= 1".into()));
        }
        Ok(())
    }
}
