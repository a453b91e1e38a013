//! Regions of space for initial conditions (`fluid.initial.regions[k].region`).

use serde::Deserialize;

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

    pub(crate) fn validate(&self, field: &str) -> Result<(), (String, String)> {
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
