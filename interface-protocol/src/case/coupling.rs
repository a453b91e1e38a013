//! `[coupling]`: the staggered scheme and its step (DESIGN §4).

use serde::Deserialize;

/// The partitioned scheme the launcher drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum Scheme {
    /// Conventional serial staggered, first order (the negative control).
    #[serde(rename = "CSS")]
    Css,
    /// Explicit-explicit, second order, fluid half a step ahead.
    C0,
    /// Implicit-explicit (implicit midpoint structure), second order, fluid half a step ahead.
    A6,
}

/// `[coupling]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingSection {
    #[serde(default = "default_scheme")]
    pub scheme: Scheme,
    /// Coupling time step Δt [s].
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// End time [s].
    #[serde(default = "default_t_end")]
    pub t_end: f64,
    /// Seconds without progress before a peer is declared unresponsive.
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
}

fn default_scheme() -> Scheme {
    Scheme::C0
}
fn default_dt() -> f64 {
    1e-4
}
fn default_t_end() -> f64 {
    1e-2
}
fn default_timeout() -> f64 {
    60.0
}

impl Default for CouplingSection {
    fn default() -> Self {
        Self {
            scheme: default_scheme(),
            dt: default_dt(),
            t_end: default_t_end(),
            timeout_s: default_timeout(),
        }
    }
}

impl CouplingSection {
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        super::require_positive("coupling.dt", self.dt)?;
        super::require_positive("coupling.t_end", self.t_end)?;
        super::require_positive("coupling.timeout_s", self.timeout_s)
    }

    /// Number of coupling steps to reach `t_end` (the last one may be shortened).
    pub fn n_steps(&self) -> u64 {
        (self.t_end / self.dt - 1e-9).ceil().max(1.0) as u64
    }
}
