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
        super::require_positive("coupling.timeout_s", self.timeout_s)?;
        if self.dt > self.t_end {
            return Err((
                "coupling.dt".into(),
                format!(
                    "the coupling step {:e} s is longer than the whole run (coupling.t_end = {:e} \
                     s); expected dt <= t_end",
                    self.dt, self.t_end
                ),
            ));
        }
        crate::resources::step_count("coupling.t_end / coupling.dt", self.t_end, self.dt)
            .map_err(|e| ("coupling.dt".to_string(), e.to_string()))?;
        Ok(())
    }

    /// Number of coupling steps to reach `t_end` (the last one may be shortened); validation keeps
    /// it within [`crate::resources::MAX_STEPS`].
    pub fn n_steps(&self) -> u64 {
        (self.t_end / self.dt - 1e-9).ceil().max(1.0) as u64
    }
}

#[cfg(test)]
mod tests {
    use crate::case::Case;
    use crate::resources::MAX_STEPS;
    use std::path::Path;

    fn parse(coupling: &str) -> Result<Case, String> {
        Case::parse(&format!("[coupling]\n{coupling}\n"), Path::new("c.toml"), &[])
            .map_err(|e| e.to_string())
    }

    #[test]
    fn a_step_longer_than_the_run_is_refused() {
        let e = parse("t_end = 1.0\ndt = 2.0").unwrap_err();
        assert!(
            e.starts_with("c.toml:3:1: field `coupling.dt`") && e.contains("dt <= t_end"),
            "{e}"
        );
        assert!(parse("t_end = 1.0\ndt = 1.0").is_ok());
    }

    #[test]
    fn a_step_count_past_the_cap_names_both_keys() {
        let e = parse("t_end = 1.0\ndt = 1e-300").unwrap_err();
        assert!(e.starts_with("c.toml:3:1: field `coupling.dt`"), "{e}");
        assert!(
            e.contains("coupling.t_end / coupling.dt") && e.contains("about 1.000e300 steps"),
            "{e}"
        );
        // At the cap it is accepted, one step past it is not.
        let at = parse(&format!("t_end = {MAX_STEPS}.0\ndt = 1.0")).unwrap();
        assert_eq!(at.coupling.n_steps(), MAX_STEPS);
        assert!(parse(&format!("t_end = {}.0\ndt = 1.0", MAX_STEPS + 1)).is_err());
        let e = Case::parse("", Path::new("c.toml"), &["coupling.dt=1e-300".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("coupling.t_end / coupling.dt"), "{e}");
    }
}
