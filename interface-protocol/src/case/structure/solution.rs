//! How `[structure]` is solved: the time integrator (or statics), the Newton controls of static
//! runs, and the displacement and arc-length controls of path-following.

use super::Dof;
use serde::Deserialize;

/// Time integration or statics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    CentralDifference,
    Newmark,
    Midpoint,
    Static,
}

impl Integrator {
    /// The name in case files.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::CentralDifference => "central_difference",
            Integrator::Newmark => "newmark",
            Integrator::Midpoint => "midpoint",
            Integrator::Static => "static",
        }
    }
}

/// `newton = { tol, max_iter, max_cuts }` of static runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonSection {
    #[serde(default)]
    pub tol: Option<f64>,
    #[serde(default)]
    pub max_iter: Option<usize>,
    #[serde(default)]
    pub max_cuts: Option<usize>,
}

/// `control = { point | set, dof, value }`: the dof driven to `value` in `steps` increments.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlSection {
    #[serde(default)]
    pub point: Option<[f64; 3]>,
    #[serde(default)]
    pub set: Option<String>,
    pub dof: Dof,
    pub value: f64,
}

/// `arc_length = { initial, min, max, desired_iterations }`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArcLengthSection {
    pub initial: f64,
    #[serde(default)]
    pub min: Option<f64>,
    #[serde(default)]
    pub max: Option<f64>,
    #[serde(default)]
    pub desired_iterations: Option<usize>,
}

impl ArcLengthSection {
    /// Smallest arc length; default `initial / 1000`.
    pub fn min(&self) -> f64 {
        self.min.unwrap_or(1e-3 * self.initial)
    }

    /// Largest arc length; default `10 initial`.
    pub fn max(&self) -> f64 {
        self.max.unwrap_or(10.0 * self.initial)
    }
}
