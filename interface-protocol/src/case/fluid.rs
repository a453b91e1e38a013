//! `[fluid]`: which fluid participant runs, and the settings of `fluid-solver` (DESIGN §5).
//!
//! Settings of `fluid-solver` are optional here (a case may couple the analytic piston fluid
//! instead); `fluid-solver` checks that what it needs is present when it runs. The EOS tables, the
//! flux and the limiter names are checked by `fluid-solver` against its own types (it owns them),
//! with the same `fluid.<field>` names in its errors.
//!
//! Fluids: either one `eos` (a single fluid, named [`SINGLE_FLUID`]) or named fluids, each a
//! `[fluid.fluids.<name>]` table with its own `eos` (not both). Material ids number the fluids in
//! ascending order of their names ([`FluidSection::materials`]); they are what the per-node
//! `material` of the solver, its lines and its field output hold. The initial background names
//! its fluid with `fluid = "<name>"` (needed when there are several) and each region may name
//! another (default: the background's).
//!
//! ```toml
//! [fluid.fluids.air]
//! eos = { kind = "perfect_gas", gamma = 1.4 }
//! [fluid.fluids.water]
//! eos = { kind = "stiffened_gas", gamma = 4.4, p_c = 6e8 }
//! [fluid.initial]
//! fluid = "air"
//! state = [1.2, 0, 0, 0, 1e5]
//! regions = [{ region = { shape = "sphere", center = [0, 0, 0], radius = 0.1 },
//!              fluid = "water", state = [1000, 0, 0, 0, 1e5] }]
//! ```
//!
//! ```toml
//! [fluid]
//! eos = { kind = "perfect_gas", gamma = 1.4 }
//! probes = [{ name = "p1", at = [0.2, 0, 0] }]
//! lines = [{ name = "axis", from = [0, 0, 0], to = [1, 0, 0], points = 201, times = [0.1] }]
//!
//! [fluid.mesh]           # see `mesh`: a box, an octant of a ball or a gmsh file
//! box = { lo = [0, 0, 0], hi = [1, 0.04, 0.04], cells = [100, 1, 1], shape = "hex" }
//!
//! [fluid.initial]
//! state = [1.0, 0.0, 0.0, 0.0, 1.0]            # [ρ, u, v, w, p] everywhere ...
//! regions = [                                  # ... then each region in order
//!   { region = { shape = "half_space", point = [0.5, 0, 0], normal = [1, 0, 0] },
//!     state = [0.125, 0, 0, 0, 0.1] },
//! ]
//!
//! [fluid.boundary]
//! xmin = { kind = "slip_wall" }
//! xmax = { kind = "far_field", state = [1, 0, 0, 0, 1] }
//!
//! [fluid.numerics]
//! flux = "roe"          # or "hllc"
//! limiter = "van_albada"  # "minmod", "unlimited", "first_order"
//! cfl = 0.5
//!
//! [fluid.time]
//! t_end = 0.2      # end of a run alone (a coupled run ends at coupling.t_end)
//! max_steps = 1000 # optional: a run alone stops after this many steps
//! substeps = 8     # optional, coupled runs: exactly 8 equal steps per coupling interval
//!                  # instead of the CFL steps (refused, naming this key, if one is unstable)
//! ```

use super::{FluidMesh, PistonFluid, Region};
use serde::Deserialize;
use std::collections::BTreeMap;

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
    /// `[fluid.mesh]`.
    #[serde(default)]
    pub mesh: Option<FluidMesh>,
    /// The equation of state of a single fluid (named [`SINGLE_FLUID`]), a table with a `kind`
    /// key (`perfect_gas`, `stiffened_gas`, `tait`).
    #[serde(default)]
    pub eos: Option<toml::Value>,
    /// `[fluid.fluids.<name>]`: named fluids, instead of `eos`.
    #[serde(default)]
    pub fluids: BTreeMap<String, NamedFluid>,
    /// `[fluid.initial]`.
    #[serde(default)]
    pub initial: Option<FluidInitial>,
    /// `[fluid.boundary]`: a condition for each named boundary of the mesh.
    #[serde(default)]
    pub boundary: BTreeMap<String, FluidBoundary>,
    /// `[fluid.numerics]`.
    #[serde(default)]
    pub numerics: FluidNumerics,
    /// `[fluid.time]`.
    #[serde(default)]
    pub time: Option<FluidTime>,
    /// `[[fluid.probes]]`: points sampled into `probes.csv`.
    #[serde(default)]
    pub probes: Vec<FluidProbe>,
    /// `[[fluid.lines]]`: straight lines sampled into `lines/<name>.csv` at given times.
    #[serde(default)]
    pub lines: Vec<FluidLine>,
    /// `[fluid.embedded]`: an embedded surface with a prescribed motion (fluid-alone runs).
    #[serde(default)]
    pub embedded: Option<super::FluidEmbedded>,
    /// `[fluid.level_set]`: the interface between two fluids moves with the flow.
    #[serde(default)]
    pub level_set: Option<super::FluidLevelSet>,
}

/// The name of the one fluid of a case that gives `fluid.eos` (not `[fluid.fluids]`).
pub const SINGLE_FLUID: &str = "fluid";

/// Most fluids a case may name (material ids are one byte).
pub const MAX_FLUIDS: usize = 256;

/// `[fluid.fluids.<name>]`: one named fluid.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedFluid {
    /// Its equation of state, a table with a `kind` key (as `fluid.eos`).
    pub eos: toml::Value,
}

/// One fluid of a case with its material id (its place in [`FluidSection::materials`]).
#[derive(Debug, Clone)]
pub struct FluidMaterial<'a> {
    pub name: &'a str,
    /// The case field of its EOS: `fluid.eos` or `fluid.fluids.<name>.eos`.
    pub eos_field: String,
    pub eos: &'a toml::Value,
}

/// `[fluid.initial]`: a background state, then regions applied in order (later ones win).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidInitial {
    /// The fluid everywhere (a name of `[fluid.fluids]`); needed when there are several.
    #[serde(default)]
    pub fluid: Option<String>,
    /// Primitive `[ρ, u, v, w, p]` everywhere.
    pub state: [f64; 5],
    #[serde(default)]
    pub regions: Vec<InitialRegion>,
}

/// A region of the initial condition and its state.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialRegion {
    pub region: Region,
    /// The fluid inside; default the background's.
    #[serde(default)]
    pub fluid: Option<String>,
    /// Primitive `[ρ, u, v, w, p]` inside.
    pub state: [f64; 5],
}

/// A boundary condition (`kind` key).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "a boundary table with a `kind` key, e.g. { kind = \"slip_wall\" }"
)]
pub enum FluidBoundary {
    SlipWall,
    Symmetry,
    /// Non-reflecting far field with the free stream `[ρ, u, v, w, p]`.
    FarField {
        state: [f64; 5],
    },
    /// Inflow of `[ρ, u, v, w, p]`.
    Inflow {
        state: [f64; 5],
    },
    /// Outflow at a static pressure.
    Outflow {
        pressure: f64,
    },
}

/// `[fluid.numerics]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidNumerics {
    /// `"roe"` or `"hllc"`.
    #[serde(default = "roe")]
    pub flux: String,
    /// MUSCL limiter: `"van_albada"`, `"minmod"`, `"unlimited"` (second order, not TVD) or
    /// `"first_order"`.
    #[serde(default = "van_albada")]
    pub limiter: String,
    /// CFL number of the explicit RK2 step.
    #[serde(default = "half")]
    pub cfl: f64,
    /// Local time stepping (steady problems only).
    #[serde(default)]
    pub local_time_step: bool,
}

fn roe() -> String {
    "roe".into()
}
fn van_albada() -> String {
    "van_albada".into()
}
fn half() -> f64 {
    0.5
}

impl Default for FluidNumerics {
    fn default() -> Self {
        FluidNumerics { flux: roe(), limiter: van_albada(), cfl: half(), local_time_step: false }
    }
}

/// `[fluid.time]`: `t_end` and `max_steps` of a run alone; `substeps` of a coupled run (where
/// the coupling step drives the fluid).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidTime {
    /// End time of a run alone (required there; a coupled run ends at `coupling.t_end`).
    #[serde(default)]
    pub t_end: Option<f64>,
    /// Stop after this many steps even before `t_end` (at most `resources::MAX_STEPS`).
    #[serde(default)]
    pub max_steps: Option<u64>,
    /// Coupled runs: the fluid takes exactly this many equal steps over each coupling interval
    /// instead of its CFL steps (so that its own time error shrinks with the coupling step, as
    /// a temporal order study needs). A step longer than the stable step (`cfl` times the CFL
    /// step, and the embedded surface's half-edge limit) stops the run, naming this key and
    /// the substeps needed. Line times are then not landed on: a line is written at the end
    /// of the first step that reaches its time. Without it the fluid subcycles in its CFL
    /// steps, the last one clipped to land on the interval's end.
    #[serde(default)]
    pub substeps: Option<u64>,
}

/// A probe point.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidProbe {
    pub name: String,
    pub at: [f64; 3],
}

/// A sampling line.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidLine {
    pub name: String,
    pub from: [f64; 3],
    pub to: [f64; 3],
    /// Number of sample points (>= 2).
    #[serde(default = "hundred")]
    pub points: usize,
    /// Times at which to write the line, each in `lines/<name>_t<time>.csv` (the step that would
    /// pass one is shortened to land on it); the final state is always written to
    /// `lines/<name>.csv`.
    #[serde(default)]
    pub times: Vec<f64>,
}

fn hundred() -> usize {
    100
}

impl FluidSection {
    /// The command that starts this participant.
    pub fn command(&self) -> Vec<String> {
        self.command.clone().unwrap_or_else(|| vec!["fluid-solver".to_string()])
    }

    /// The fluids by material id (ascending names): the one fluid [`SINGLE_FLUID`] of `eos`, or
    /// those of `[fluid.fluids]`; empty when neither is given.
    pub fn materials(&self) -> Vec<FluidMaterial<'_>> {
        match &self.eos {
            Some(eos) => {
                vec![FluidMaterial { name: SINGLE_FLUID, eos_field: "fluid.eos".into(), eos }]
            }
            None => self
                .fluids
                .iter()
                .map(|(name, f)| FluidMaterial {
                    name,
                    eos_field: format!("fluid.fluids.{name}.eos"),
                    eos: &f.eos,
                })
                .collect(),
        }
    }

    /// The material id of the fluid `name` ([`FluidSection::materials`]).
    pub fn material_id(&self, name: &str) -> Option<usize> {
        self.materials().iter().position(|m| m.name == name)
    }

    /// The material ids of the initial background and of each initial region, in order (a region
    /// without `fluid` takes the background's; a background without one the only fluid).
    /// `None` where the case's validation refuses the names.
    pub fn initial_materials(&self) -> Option<(usize, Vec<usize>)> {
        let init = self.initial.as_ref()?;
        let background = match &init.fluid {
            Some(name) => self.material_id(name)?,
            None if self.materials().len() == 1 => 0,
            None => return None,
        };
        let regions = init
            .regions
            .iter()
            .map(|r| r.fluid.as_ref().map_or(Some(background), |name| self.material_id(name)))
            .collect::<Option<Vec<usize>>>()?;
        Some((background, regions))
    }

    /// Checks the fluid names: `eos` or `fluids`, not both; names known where they are used.
    fn validate_fluids(&self) -> Result<(), (String, String)> {
        if self.eos.is_some() && !self.fluids.is_empty() {
            return Err((
                "fluid.fluids".into(),
                format!(
                    "give either `eos` (one fluid, named `{SINGLE_FLUID}`) or `[fluid.fluids.<name>]` \
                     tables with an `eos` each, not both"
                ),
            ));
        }
        if let Some(name) = self.fluids.keys().find(|n| n.is_empty()) {
            return Err((format!("fluid.fluids.{name}"), "a fluid needs a non-empty name".into()));
        }
        if self.fluids.len() > MAX_FLUIDS {
            return Err((
                "fluid.fluids".into(),
                format!("{} fluids, at most {MAX_FLUIDS} are supported", self.fluids.len()),
            ));
        }
        let materials = self.materials();
        let known = || {
            if materials.is_empty() {
                "the case defines no fluid (give `eos` or `[fluid.fluids.<name>]`)".to_string()
            } else {
                let names: Vec<&str> = materials.iter().map(|m| m.name).collect();
                format!("the case's fluids are: {}", names.join(", "))
            }
        };
        let check = |field: String, name: &Option<String>| match name {
            Some(n) if !materials.iter().any(|m| m.name == n) => {
                Err((field, format!("unknown fluid `{n}`; {}", known())))
            }
            _ => Ok(()),
        };
        if let Some(init) = &self.initial {
            check("fluid.initial.fluid".into(), &init.fluid)?;
            if init.fluid.is_none() && materials.len() > 1 {
                return Err((
                    "fluid.initial.fluid".into(),
                    format!(
                        "missing: with several fluids the background needs one, e.g. fluid = \
                         \"{}\"; {}",
                        materials[0].name,
                        known()
                    ),
                ));
            }
            for (k, r) in init.regions.iter().enumerate() {
                check(format!("fluid.initial.regions[{k}].fluid"), &r.fluid)?;
            }
        }
        Ok(())
    }

    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        self.validate_fluids()?;
        if let Some(p) = &self.piston {
            p.validate()?;
        }
        if let Some(m) = &self.mesh {
            m.validate()?;
        }
        let state_ok = |field: &str, s: &[f64; 5]| -> Result<(), (String, String)> {
            if s.iter().any(|v| !v.is_finite()) || s[0] <= 0.0 {
                return Err((
                    field.to_string(),
                    format!("expected a finite [ρ, u, v, w, p] with ρ > 0, got {s:?}"),
                ));
            }
            Ok(())
        };
        if let Some(init) = &self.initial {
            state_ok("fluid.initial.state", &init.state)?;
            for (k, r) in init.regions.iter().enumerate() {
                r.region.validate(&format!("fluid.initial.regions[{k}].region"))?;
                state_ok(&format!("fluid.initial.regions[{k}].state"), &r.state)?;
            }
        }
        for (name, b) in &self.boundary {
            match b {
                FluidBoundary::FarField { state } | FluidBoundary::Inflow { state } => {
                    state_ok(&format!("fluid.boundary.{name}.state"), state)?
                }
                FluidBoundary::Outflow { pressure } if !pressure.is_finite() => {
                    return Err((
                        format!("fluid.boundary.{name}.pressure"),
                        "expected a finite pressure".into(),
                    ))
                }
                _ => {}
            }
        }
        let n = &self.numerics;
        if !(n.cfl > 0.0 && n.cfl <= 1.0) {
            return Err((
                "fluid.numerics.cfl".into(),
                format!("expected 0 < cfl <= 1, got {}", n.cfl),
            ));
        }
        if !matches!(n.flux.as_str(), "roe" | "hllc") {
            return Err((
                "fluid.numerics.flux".into(),
                format!("expected \"roe\" or \"hllc\", got \"{}\"", n.flux),
            ));
        }
        if !matches!(n.limiter.as_str(), "van_albada" | "minmod" | "unlimited" | "first_order") {
            return Err((
                "fluid.numerics.limiter".into(),
                format!(
                    "expected \"van_albada\", \"minmod\", \"unlimited\" or \"first_order\", got \"{}\"",
                    n.limiter
                ),
            ));
        }
        if let Some(t) = &self.time {
            if let Some(t_end) = t.t_end {
                super::require_positive("fluid.time.t_end", t_end)?;
            }
            let cap = crate::resources::MAX_STEPS;
            match t.substeps {
                Some(0) => {
                    return Err((
                        "fluid.time.substeps".into(),
                        "expected at least 1 step per coupling interval, got 0".into(),
                    ))
                }
                Some(m) if m > cap => {
                    return Err((
                        "fluid.time.substeps".into(),
                        format!("expected at most {cap} steps per coupling interval, got {m}"),
                    ))
                }
                Some(_) if n.local_time_step => {
                    return Err((
                        "fluid.time.substeps".into(),
                        "fixed substeps are time accurate steps of one length for all nodes; \
                         they cannot be combined with fluid.numerics.local_time_step = true"
                            .into(),
                    ))
                }
                _ => {}
            }
            let cap = crate::resources::MAX_STEPS;
            if let Some(m) = t.max_steps.filter(|&m| m > cap) {
                return Err((
                    "fluid.time.max_steps".into(),
                    format!("expected at most {cap} steps, got {m}"),
                ));
            }
        }
        for (k, l) in self.lines.iter().enumerate() {
            if l.points < 2 {
                return Err((
                    format!("fluid.lines[{k}].points"),
                    "expected at least 2 points".into(),
                ));
            }
            if let Some((j, t)) =
                l.times.iter().enumerate().find(|(_, t)| !(**t >= 0.0 && t.is_finite()))
            {
                return Err((
                    format!("fluid.lines[{k}].times[{j}]"),
                    format!("expected a finite time >= 0, got {t}"),
                ));
            }
        }
        if let Some(e) = &self.embedded {
            e.validate()?;
        }
        if let Some(l) = &self.level_set {
            l.validate(&self.materials())?;
        }
        let mut names: Vec<&str> = self.probes.iter().map(|p| p.name.as_str()).collect();
        names.sort_unstable();
        if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
            return Err(("fluid.probes".into(), format!("probe name `{}` is used twice", w[0])));
        }
        Ok(())
    }
}

#[cfg(test)]
#[path = "fluid_tests.rs"]
mod tests;
