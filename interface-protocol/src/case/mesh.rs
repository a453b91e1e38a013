//! `[fluid.mesh]`: a box, an octant of a ball, or a gmsh file.
//!
//! ```toml
//! [fluid.mesh]
//! box = { lo = [0, 0, 0], hi = [1, 0.04, 0.04], cells = [100, 1, 1], shape = "hex" }
//! # or: octant = { core = 0.03, cells = 18, radius = 1.6, grading = 1.15, coarsen = [0.06] }
//! # or: file = "mesh.msh"  (gmsh 4.1, physical groups name the boundaries)
//! ```

use serde::Deserialize;

/// `[fluid.mesh]`: a box mesh, an octant mesh or a gmsh file (exactly one).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidMesh {
    #[serde(default, rename = "box")]
    pub box_mesh: Option<BoxMesh>,
    #[serde(default)]
    pub octant: Option<OctantMesh>,
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
    /// Cells along each axis, from `lo`, of equal size before the grading starts; default none
    /// (graded from the first cell).
    #[serde(default)]
    pub core: [usize; 3],
    #[serde(default)]
    pub shape: BoxShape,
}

fn ones() -> [f64; 3] {
    [1.0; 3]
}

/// `fluid.mesh.octant`: hexes filling the octant `x, y, z >= 0` of the ball of radius `radius`
/// about the origin: a uniform cube `[0, core]³` of `cells` hexes per edge, then layers of the
/// same spacing out to `fine` (along the axes), then layers growing by `grading`. Boundaries are
/// named `xmin, ymin, zmin` (the planes) and `outer` (the sphere).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OctantMesh {
    pub core: f64,
    pub cells: usize,
    /// Default: `core` (the layers grow from the cube on).
    #[serde(default)]
    pub fine: Option<f64>,
    pub radius: f64,
    pub grading: f64,
    /// Radii (ascending, beyond `fine`) past which the layers' faces have half as many cells
    /// along each side (each halving needs an even count); default none.
    #[serde(default)]
    pub coarsen: Vec<f64>,
}

impl FluidMesh {
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        let given = [self.box_mesh.is_some(), self.octant.is_some(), self.file.is_some()];
        if given.iter().filter(|&&g| g).count() != 1 {
            return Err((
                "fluid.mesh".into(),
                "expected exactly one of `box = {...}`, `octant = {...}` or `file = \"mesh.msh\"`"
                    .into(),
            ));
        }
        if let Some(b) = &self.box_mesh {
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
                        format!("expected hi > lo on every axis, got lo {:?}, hi {:?}", b.lo, b.hi),
                    ));
                }
                super::require_positive("fluid.mesh.box.grading", b.grading[k])?;
                if b.core[k] > b.cells[k] {
                    return Err((
                        "fluid.mesh.box.core".into(),
                        format!(
                            "expected at most the cells per axis, got core {:?}, cells {:?}",
                            b.core, b.cells
                        ),
                    ));
                }
            }
        }
        if let Some(o) = &self.octant {
            super::require_positive("fluid.mesh.octant.core", o.core)?;
            if o.cells == 0 {
                return Err(("fluid.mesh.octant.cells".into(), "expected >= 1 cell".into()));
            }
            let diagonal = o.core * 3f64.sqrt();
            if !(o.radius.is_finite() && o.radius > diagonal) {
                return Err((
                    "fluid.mesh.octant.radius".into(),
                    format!(
                        "expected more than the core's diagonal {diagonal} (core {}), got {}",
                        o.core, o.radius
                    ),
                ));
            }
            if let Some(fine) = o.fine {
                if !(fine.is_finite() && fine >= o.core && fine <= o.radius) {
                    return Err((
                        "fluid.mesh.octant.fine".into(),
                        format!("expected core <= fine <= radius, got {fine}"),
                    ));
                }
            }
            let mut m = o.cells;
            for (k, &r) in o.coarsen.iter().enumerate() {
                let after =
                    o.fine.unwrap_or(o.core).max(if k > 0 { o.coarsen[k - 1] } else { 0.0 });
                if m % 2 != 0 || !(r.is_finite() && r > after && r < o.radius) {
                    return Err((
                        format!("fluid.mesh.octant.coarsen[{k}]"),
                        format!(
                            "expected ascending radii beyond `fine` and below `radius`, each \
                             halving an even count of cells ({m} here), got {r}"
                        ),
                    ));
                }
                m /= 2;
            }
            if !(o.grading.is_finite() && o.grading > 1.0) {
                return Err((
                    "fluid.mesh.octant.grading".into(),
                    format!("expected a ratio > 1, got {}", o.grading),
                ));
            }
        }
        Ok(())
    }
}
