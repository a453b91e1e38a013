//! `[fluid]`: which fluid participant runs, and the settings of `fluid-solver` (DESIGN §5).
//!
//! Settings of `fluid-solver` are optional here (a case may couple the analytic piston fluid
//! instead); `fluid-solver` checks that what it needs is present when it runs. The EOS table, the
//! flux and the limiter names are checked by `fluid-solver` against its own types (it owns them),
//! with the same `fluid.<field>` names in its errors.
//!
//! ```toml
//! [fluid]
//! eos = { kind = "perfect_gas", gamma = 1.4 }
//! probes = [{ name = "p1", at = [0.2, 0, 0] }]
//! lines = [{ name = "axis", from = [0, 0, 0], to = [1, 0, 0], points = 201, times = [0.1] }]
//!
//! [fluid.mesh]
//! box = { lo = [0, 0, 0], hi = [1, 0.04, 0.04], cells = [100, 1, 1], shape = "hex" }
//! # or: file = "mesh.msh"  (gmsh 4.1, physical groups name the boundaries)
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
//! t_end = 0.2
//! ```

use super::PistonFluid;
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
    /// The equation of state, a table with a `kind` key (`perfect_gas`, `stiffened_gas`, `tait`).
    #[serde(default)]
    pub eos: Option<toml::Value>,
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
}

/// `[fluid.mesh]`: a box mesh or a gmsh file (exactly one).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidMesh {
    #[serde(default, rename = "box")]
    pub box_mesh: Option<BoxMesh>,
    /// A gmsh 4.1 `.msh` file, relative to the case file.
    #[serde(default)]
    pub file: Option<String>,
}

/// Cell shape of a box mesh.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BoxShape {
    #[default]
    Hex,
    /// Each hex split into 6 tets.
    Tet,
}

/// `fluid.mesh.box`: faces are named `xmin, xmax, ymin, ymax, zmin, zmax`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxMesh {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    /// Cells per axis (1 across y and z makes a one-cell-thick tube).
    pub cells: [usize; 3],
    /// Ratio of successive cell sizes along each axis; default uniform.
    #[serde(default = "ones")]
    pub grading: [f64; 3],
    #[serde(default)]
    pub shape: BoxShape,
}

fn ones() -> [f64; 3] {
    [1.0; 3]
}

/// `[fluid.initial]`: a background state, then regions applied in order (later ones win).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidInitial {
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
    /// Primitive `[ρ, u, v, w, p]` inside.
    pub state: [f64; 5],
}

/// A region of space (points on its surface count as inside).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(
    tag = "shape",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "a region table with a `shape` key, e.g. { shape = \"box\", lo = [...], hi = [...] }"
)]
pub enum Region {
    /// `(x - point) · normal >= 0`.
    HalfSpace {
        point: [f64; 3],
        normal: [f64; 3],
    },
    /// Axis-aligned box.
    Box {
        lo: [f64; 3],
        hi: [f64; 3],
    },
    Sphere {
        center: [f64; 3],
        radius: f64,
    },
    /// Finite cylinder along the segment `start -> end`.
    Cylinder {
        start: [f64; 3],
        end: [f64; 3],
        radius: f64,
    },
}

impl Region {
    /// True if `x` is inside or on the surface.
    pub fn contains(&self, x: [f64; 3]) -> bool {
        let d = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        match *self {
            Region::HalfSpace { point, normal } => dot(d(x, point), normal) >= 0.0,
            Region::Box { lo, hi } => (0..3).all(|k| x[k] >= lo[k] && x[k] <= hi[k]),
            Region::Sphere { center, radius } => dot(d(x, center), d(x, center)) <= radius * radius,
            Region::Cylinder { start, end, radius } => {
                let axis = d(end, start);
                let r = d(x, start);
                let t = dot(r, axis) / dot(axis, axis);
                let radial = dot(r, r) - t * t * dot(axis, axis);
                (0.0..=1.0).contains(&t) && radial <= radius * radius
            }
        }
    }

    fn validate(&self, field: &str) -> Result<(), (String, String)> {
        let bad = |msg: String| Err((field.to_string(), msg));
        match *self {
            Region::HalfSpace { normal, .. } => {
                if normal.iter().all(|c| *c == 0.0) || normal.iter().any(|c| !c.is_finite()) {
                    return bad("half_space: `normal` must be a finite non-zero vector".into());
                }
            }
            Region::Box { lo, hi } => {
                if (0..3).any(|k| hi[k].partial_cmp(&lo[k]).is_none_or(|o| o.is_lt())) {
                    return bad(format!(
                        "box: expected hi >= lo per axis, got lo {lo:?}, hi {hi:?}"
                    ));
                }
            }
            Region::Sphere { radius, .. } => {
                super::require_positive(&format!("{field}.radius"), radius)?
            }
            Region::Cylinder { start, end, radius } => {
                super::require_positive(&format!("{field}.radius"), radius)?;
                if start == end {
                    return bad("cylinder: `start` and `end` must differ".into());
                }
            }
        }
        Ok(())
    }
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

/// `[fluid.time]` (alone; coupled, the coupling step drives the fluid).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidTime {
    /// End time.
    pub t_end: f64,
    /// Stop after this many steps even before `t_end` (at most `resources::MAX_STEPS`).
    #[serde(default)]
    pub max_steps: Option<u64>,
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

    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        if let Some(p) = &self.piston {
            p.validate()?;
        }
        if let Some(m) = &self.mesh {
            match (&m.box_mesh, &m.file) {
                (Some(_), Some(_)) | (None, None) => {
                    return Err((
                        "fluid.mesh".into(),
                        "expected exactly one of `box = {...}` or `file = \"mesh.msh\"`".into(),
                    ))
                }
                (Some(b), None) => {
                    for k in 0..3 {
                        if b.cells[k] == 0 {
                            return Err((
                                "fluid.mesh.box.cells".into(),
                                "expected >= 1 cell per axis".into(),
                            ));
                        }
                        if b.hi[k].partial_cmp(&b.lo[k]).is_none_or(|o| o.is_le()) {
                            return Err((
                                "fluid.mesh.box.hi".into(),
                                format!(
                                    "expected hi > lo on every axis, got lo {:?}, hi {:?}",
                                    b.lo, b.hi
                                ),
                            ));
                        }
                        super::require_positive("fluid.mesh.box.grading", b.grading[k])?;
                    }
                }
                (None, Some(_)) => {}
            }
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
            super::require_positive("fluid.time.t_end", t.t_end)?;
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
        let mut names: Vec<&str> = self.probes.iter().map(|p| p.name.as_str()).collect();
        names.sort_unstable();
        if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
            return Err(("fluid.probes".into(), format!("probe name `{}` is used twice", w[0])));
        }
        Ok(())
    }
}
