//! `[fluid.embedded]`: a structure surface embedded in the fluid grid (thesis Ch. 4-5): its
//! geometry (a gmsh surface mesh or a generator), a prescribed rigid motion, the tracking and
//! loads algorithms, and the seeds of the node-status flood fill.
//!
//! A fluid-alone run needs `surface` and may give `motion`. A coupled run takes the surface and
//! its motion from the structure over the protocol: there `surface` and `motion` do not apply
//! (`fluid-solver` refuses them), and `tracking`, `loads`, `seeds` and `p_cut` do.
//!
//! ```toml
//! [fluid.embedded]
//! surface = { generator = "sphere", center = [0, 0, 0], radius = 0.2, refinement = 3 }
//! # or { generator = "box", lo = [...], hi = [...], cells = [4, 4, 4] }
//! # or { generator = "plate", corner = [...], edge_u = [...], edge_v = [...], cells = [8, 8] }
//! # or { generator = "cylinder", start = [...], end = [...], radius = 0.1, cells = [32, 8], capped = true }
//! # or { file = "plate.msh" }   (gmsh 4.1 triangles and quads)
//! motion = { kind = "translation", velocity = [10, 0, 0] }
//! # or { kind = "harmonic", amplitude = [0.08, 0, 0], frequency = 100, form = "one_minus_cos" }
//! # or { kind = "rotation", center = [...], axis = [0, 0, 1], omega = 2.0 }
//! # or { kind = "tabulated", times = [0, 1e-3], displacements = [[0, 0, 0], [1e-3, 0, 0]] }
//! tracking = "collision"   # Alg. 4.2 (default; open, thin surfaces) or "projection" (Alg. 4.1)
//! loads = "reconstructed"  # Alg. 5.3 (default) or "facets" (Alg. 5.4)
//! interface = "second_order" # Alg. 5.1 at the reconstructed interface (default) or "first_order"
//! seeds = [{ at = [0, 0, 0], active = false }]   # flood-fill seeds at t = 0
//! ```
//!
//! Without `seeds`, every node not separated from the far boundary is active; a closed surface
//! needs a seed inside it to say whether that fluid is active (a second fluid) or not (a solid
//! body).

use serde::Deserialize;

/// `[fluid.embedded]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidEmbedded {
    /// The surface of a fluid-alone run; a coupled run takes it from the structure over the
    /// protocol and refuses this key (and `motion`).
    #[serde(default)]
    pub surface: Option<EmbeddedSurface>,
    #[serde(default)]
    pub motion: Option<Motion>,
    #[serde(default)]
    pub tracking: Tracking,
    #[serde(default)]
    pub loads: LoadAlgorithm,
    #[serde(default)]
    pub interface: InterfaceTreatment,
    #[serde(default)]
    pub seeds: Vec<Seed>,
    /// Cavitation cut-off: star and nodal pressures below it are clipped to it (Pa).
    #[serde(default)]
    pub p_cut: Option<f64>,
}

/// The geometry of an embedded surface: a file or a generator.
#[derive(Debug, Clone, PartialEq)]
pub enum EmbeddedSurface {
    /// A gmsh 4.1 surface mesh (triangles and quads), relative to the case file.
    File {
        file: String,
    },
    Generated {
        generator: SurfaceGenerator,
    },
}

impl<'de> Deserialize<'de> for EmbeddedSurface {
    /// `{ file = "..." }` or a generator table: the generator's own errors (unknown key, missing
    /// field) are kept, rather than an untagged "no variant matched".
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let table = toml::Table::deserialize(d)?;
        if table.contains_key("file") {
            #[derive(Deserialize)]
            #[serde(deny_unknown_fields)]
            struct File {
                file: String,
            }
            let f: File = toml::Value::Table(table).try_into().map_err(D::Error::custom)?;
            return Ok(EmbeddedSurface::File { file: f.file });
        }
        if !table.contains_key("generator") {
            return Err(D::Error::custom(
                "expected { file = \"surface.msh\" } or { generator = \"sphere\" | \"box\" | \"plate\" | \"cylinder\", ... }",
            ));
        }
        let generator = toml::Value::Table(table).try_into().map_err(D::Error::custom)?;
        Ok(EmbeddedSurface::Generated { generator })
    }
}

/// A generated surface (`generator` key). Closed surfaces are wound with outward normals.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(tag = "generator", rename_all = "snake_case", deny_unknown_fields)]
pub enum SurfaceGenerator {
    /// An icosphere: 20 · 4^refinement triangles.
    Sphere {
        center: [f64; 3],
        radius: f64,
        #[serde(default = "three")]
        refinement: u32,
    },
    /// The closed surface of an axis-aligned box, `cells` quads per edge along each axis.
    Box { lo: [f64; 3], hi: [f64; 3], cells: [u32; 3] },
    /// An open flat plate `corner + s edge_u + t edge_v`, `s, t ∈ [0, 1]`.
    Plate { corner: [f64; 3], edge_u: [f64; 3], edge_v: [f64; 3], cells: [u32; 2] },
    /// A cylinder along `start -> end`, `cells = [around, along]`, with end caps when `capped`.
    Cylinder {
        start: [f64; 3],
        end: [f64; 3],
        radius: f64,
        cells: [u32; 2],
        #[serde(default)]
        capped: bool,
    },
}

fn three() -> u32 {
    3
}

/// A prescribed rigid motion of the surface: `x(t) = c + R(t)(X - c) + d(t)`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "a motion table with a `kind` key: translation, harmonic, rotation or tabulated"
)]
pub enum Motion {
    /// `d(t) = velocity · t`.
    Translation { velocity: [f64; 3] },
    /// `d(t) = amplitude (1 - cos ωt)` (`form = "one_minus_cos"`, the default) or
    /// `amplitude sin ωt` (`"sine"`), `ω = 2π frequency`.
    Harmonic {
        amplitude: [f64; 3],
        frequency: f64,
        #[serde(default)]
        form: HarmonicForm,
    },
    /// Rotation at a constant rate `omega` (rad/s) about `axis` through `center`.
    Rotation { center: [f64; 3], axis: [f64; 3], omega: f64 },
    /// Displacements at increasing times, interpolated linearly (constant after the last).
    Tabulated { times: Vec<f64>, displacements: Vec<[f64; 3]> },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HarmonicForm {
    #[default]
    OneMinusCos,
    Sine,
}

/// The tracking algorithm (thesis Ch. 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Tracking {
    /// Alg. 4.1: projection and flood fill (closed surfaces the grid resolves).
    Projection,
    /// Alg. 4.2: collision based (open, thin and unresolved surfaces).
    #[default]
    Collision,
}

/// The load algorithm (thesis §5.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadAlgorithm {
    /// Alg. 5.3: reconstructed interface, virtual-work distribution.
    #[default]
    Reconstructed,
    /// Alg. 5.4: control-volume facets.
    Facets,
}

/// Where the cut-edge fluxes of Alg. 5.1 take their states (thesis Alg. 5.1; Main, Zeng, Avery &
/// Farhat 2017).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InterfaceTreatment {
    /// The node state, the wall state at the node's facet (the thesis' form).
    FirstOrder,
    /// The node state reconstructed to the intersection point, the flux from states on the line
    /// through the wall's star state.
    #[default]
    SecondOrder,
}

/// A flood-fill seed: the node nearest `at` and every node reached from it without crossing the
/// surface are `active` (fluid) or not (inside a solid body).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Seed {
    pub at: [f64; 3],
    #[serde(default = "yes")]
    pub active: bool,
}

fn yes() -> bool {
    true
}

impl FluidEmbedded {
    /// Checks values serde cannot: positive sizes, non-zero axes, increasing tables.
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        let f = "fluid.embedded";
        let bad = |field: &str, msg: String| Err((format!("{f}.{field}"), msg));
        let finite = |field: &str, v: &[f64]| -> Result<(), (String, String)> {
            match v.iter().find(|x| !x.is_finite()) {
                Some(x) => bad(field, format!("expected finite numbers, got {x}")),
                None => Ok(()),
            }
        };
        if let Some(EmbeddedSurface::Generated { generator }) = &self.surface {
            match *generator {
                SurfaceGenerator::Sphere { center, radius, refinement } => {
                    finite("surface.center", &center)?;
                    super::require_positive(&format!("{f}.surface.radius"), radius)?;
                    if refinement > 7 {
                        return bad(
                            "surface.refinement",
                            format!("expected at most 7 (327,680 triangles), got {refinement}"),
                        );
                    }
                }
                SurfaceGenerator::Box { lo, hi, cells } => {
                    finite("surface.lo", &lo)?;
                    finite("surface.hi", &hi)?;
                    if (0..3).any(|k| hi[k] <= lo[k]) {
                        return bad(
                            "surface.hi",
                            format!("expected hi > lo on every axis, got lo {lo:?}, hi {hi:?}"),
                        );
                    }
                    if cells.contains(&0) {
                        return bad("surface.cells", "expected >= 1 cell per axis".into());
                    }
                }
                SurfaceGenerator::Plate { corner, edge_u, edge_v, cells } => {
                    finite("surface.corner", &corner)?;
                    finite("surface.edge_u", &edge_u)?;
                    finite("surface.edge_v", &edge_v)?;
                    let c = [
                        edge_u[1] * edge_v[2] - edge_u[2] * edge_v[1],
                        edge_u[2] * edge_v[0] - edge_u[0] * edge_v[2],
                        edge_u[0] * edge_v[1] - edge_u[1] * edge_v[0],
                    ];
                    if c.iter().all(|x| *x == 0.0) {
                        return bad(
                            "surface.edge_v",
                            "`edge_u` and `edge_v` must be non-zero and not parallel".into(),
                        );
                    }
                    if cells.contains(&0) {
                        return bad("surface.cells", "expected >= 1 cell per direction".into());
                    }
                }
                SurfaceGenerator::Cylinder { start, end, radius, cells, .. } => {
                    finite("surface.start", &start)?;
                    finite("surface.end", &end)?;
                    super::require_positive(&format!("{f}.surface.radius"), radius)?;
                    if start == end {
                        return bad("surface.end", "`start` and `end` must differ".into());
                    }
                    if cells[0] < 3 || cells[1] == 0 {
                        return bad(
                            "surface.cells",
                            format!("expected [around >= 3, along >= 1], got {cells:?}"),
                        );
                    }
                }
            }
        }
        match &self.motion {
            Some(Motion::Translation { velocity }) => finite("motion.velocity", velocity)?,
            Some(Motion::Harmonic { amplitude, frequency, .. }) => {
                finite("motion.amplitude", amplitude)?;
                super::require_positive(&format!("{f}.motion.frequency"), *frequency)?;
            }
            Some(Motion::Rotation { center, axis, omega }) => {
                finite("motion.center", center)?;
                finite("motion.axis", axis)?;
                finite("motion.omega", &[*omega])?;
                if axis.iter().all(|x| *x == 0.0) {
                    return bad("motion.axis", "expected a non-zero axis".into());
                }
            }
            Some(Motion::Tabulated { times, displacements }) => {
                if times.is_empty() || times.len() != displacements.len() {
                    return bad(
                        "motion.displacements",
                        format!(
                            "expected one displacement per time ({} times, {} displacements)",
                            times.len(),
                            displacements.len()
                        ),
                    );
                }
                finite("motion.times", times)?;
                if let Some(k) = times.windows(2).position(|w| w[1] <= w[0]) {
                    return bad(
                        &format!("motion.times[{}]", k + 1),
                        format!(
                            "expected increasing times, got {} after {}",
                            times[k + 1],
                            times[k]
                        ),
                    );
                }
                for (k, d) in displacements.iter().enumerate() {
                    finite(&format!("motion.displacements[{k}]"), d)?;
                }
            }
            None => {}
        }
        for (k, s) in self.seeds.iter().enumerate() {
            finite(&format!("seeds[{k}].at"), &s.at)?;
        }
        if let Some(p) = self.p_cut {
            finite("p_cut", &[p])?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Case, CaseError};
    use super::*;
    use std::path::Path;

    fn parse(body: &str) -> Result<Case, CaseError> {
        let text = format!("[fluid.embedded]\n{body}");
        Case::parse(&text, Path::new("cases/t/case.toml"), &[])
    }

    fn embedded(body: &str) -> FluidEmbedded {
        parse(body).unwrap().fluid.unwrap().embedded.unwrap()
    }

    #[test]
    fn generators_files_motions_and_defaults_parse() {
        let e =
            embedded("surface = { generator = \"sphere\", center = [0, 0, 0], radius = 0.5 }\n");
        assert_eq!(
            e.surface,
            Some(EmbeddedSurface::Generated {
                generator: SurfaceGenerator::Sphere {
                    center: [0.0; 3],
                    radius: 0.5,
                    refinement: 3
                }
            })
        );
        assert_eq!(
            (e.tracking, e.loads, e.motion),
            (Tracking::Collision, LoadAlgorithm::Reconstructed, None)
        );
        let e = embedded(
            "surface = { file = \"plate.msh\" }\ntracking = \"projection\"\nloads = \"facets\"\n\
             motion = { kind = \"harmonic\", amplitude = [0.08, 0, 0], frequency = 100 }\n\
             seeds = [{ at = [0, 0, 0], active = false }]\n",
        );
        assert_eq!(e.surface, Some(EmbeddedSurface::File { file: "plate.msh".into() }));
        assert_eq!(e.loads, LoadAlgorithm::Facets);
        assert_eq!(e.interface, InterfaceTreatment::SecondOrder);
        let first = embedded("surface = { file = \"p.msh\" }\ninterface = \"first_order\"\n");
        assert_eq!(first.interface, InterfaceTreatment::FirstOrder);
        assert_eq!(
            e.motion,
            Some(Motion::Harmonic {
                amplitude: [0.08, 0.0, 0.0],
                frequency: 100.0,
                form: HarmonicForm::OneMinusCos
            })
        );
        assert!(!e.seeds[0].active);
    }

    #[test]
    fn bad_surfaces_and_motions_name_the_field() {
        let cases = [
            ("surface = { generator = \"sphere\", center = [0, 0, 0], radius = -1 }\n", "fluid.embedded.surface.radius"),
            ("surface = { generator = \"sphere\", center = [0, 0, 0], radius = 1, refinement = 9 }\n", "fluid.embedded.surface.refinement"),
            ("surface = { generator = \"plate\", corner = [0, 0, 0], edge_u = [1, 0, 0], edge_v = [2, 0, 0], cells = [2, 2] }\n", "fluid.embedded.surface.edge_v"),
            ("surface = { generator = \"box\", lo = [0, 0, 0], hi = [1, 1, 1], cells = [1, 0, 1] }\n", "fluid.embedded.surface.cells"),
            ("surface = { file = \"a.msh\" }\nmotion = { kind = \"tabulated\", times = [0, 1, 1], displacements = [[0, 0, 0], [1, 0, 0], [2, 0, 0]] }\n", "fluid.embedded.motion.times[2]"),
            ("surface = { file = \"a.msh\" }\nmotion = { kind = \"rotation\", center = [0, 0, 0], axis = [0, 0, 0], omega = 1 }\n", "fluid.embedded.motion.axis"),
        ];
        for (body, field) in cases {
            let e = parse(body).unwrap_err();
            assert_eq!(e.field.as_deref(), Some(field), "{e}");
        }
        let e = parse("surface = { generator = \"sphere\", centre = [0, 0, 0], radius = 1 }\n")
            .unwrap_err();
        assert!(e.to_string().contains("centre"), "{e}");
        let e = parse("surface = { radius = 1 }\n").unwrap_err();
        assert!(e.to_string().contains("generator"), "{e}");
        let e =
            parse("surface = { file = \"a.msh\" }\nmotion = { kind = \"wobble\" }\n").unwrap_err();
        assert!(e.to_string().contains("translation"), "{e}");
    }
}
