//! The box mesher: a graded structured grid of hexes, or of hexes split into 6 tets, with its
//! faces named `xmin, xmax, ymin, ymax, zmin, zmax`. One cell across y and z gives the
//! one-cell-thick tubes on which 1D problems run (thesis §5.2 runs 1D problems this way).

use super::geometry::sub;
use super::{Cell, CellKind, MeshError, RawMesh, TaggedFace};

/// Names of the six faces, in the order (axis, min/max).
pub const FACE_NAMES: [&str; 6] = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];

/// Cell shape of a box mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoxCells {
    Hex,
    /// Each hex split into 6 tets around its main diagonal (Kuhn), conforming across hexes.
    Tet,
}

/// A box `[lo, hi]` with `cells[d]` cells along axis `d` and geometric grading: the first
/// `core[d]` cells along axis `d` (from `lo`) are equal, and each cell after them is `grading[d]`
/// times the previous one (1 = uniform; `core` 0 or 1 = graded from the first cell).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxSpec {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub cells: [usize; 3],
    pub grading: [f64; 3],
    pub core: [usize; 3],
    pub shape: BoxCells,
}

impl BoxSpec {
    /// A uniform box.
    pub fn uniform(lo: [f64; 3], hi: [f64; 3], cells: [usize; 3], shape: BoxCells) -> BoxSpec {
        BoxSpec { lo, hi, cells, grading: [1.0; 3], core: [0; 3], shape }
    }

    /// A one-cell-thick tube along x over `[x0, x1]` with a square section of side `width`.
    pub fn tube(x0: f64, x1: f64, n: usize, width: f64, shape: BoxCells) -> BoxSpec {
        BoxSpec::uniform([x0, 0.0, 0.0], [x1, width, width], [n, 1, 1], shape)
    }

    /// Node coordinates along axis `d`.
    fn axis(&self, d: usize) -> Vec<f64> {
        let n = self.cells[d];
        let r = self.grading[d];
        let core = self.core[d].clamp(1, n);
        // Cell sizes relative to the first: 1 over the core, then r, r², ...
        let mut t = Vec::with_capacity(n + 1);
        let (mut x, mut h) = (0.0, 1.0);
        t.push(x);
        for k in 0..n {
            if k >= core {
                h *= r;
            }
            x += h;
            t.push(x);
        }
        let total = x;
        t.iter().map(|s| self.lo[d] + s / total * (self.hi[d] - self.lo[d])).collect()
    }

    /// Builds the raw mesh.
    pub fn raw(&self) -> Result<RawMesh, MeshError> {
        for d in 0..3 {
            if self.cells[d] == 0 || self.hi[d].partial_cmp(&self.lo[d]).is_none_or(|o| o.is_le()) {
                return Err(MeshError::Input(format!(
                    "box mesh: axis {d} needs at least one cell and hi > lo (cells {}, lo {}, hi {})",
                    self.cells[d], self.lo[d], self.hi[d]
                )));
            }
            if self.core[d] > self.cells[d] {
                return Err(MeshError::Input(format!(
                    "box mesh: axis {d} has {} cells, fewer than its core of {}",
                    self.cells[d], self.core[d]
                )));
            }
            if !(self.grading[d].is_finite() && self.grading[d] > 0.0) {
                return Err(MeshError::Input(format!(
                    "box mesh: grading along axis {d} must be > 0, got {}",
                    self.grading[d]
                )));
            }
        }
        let [nx, ny, nz] = self.cells;
        let axes = [self.axis(0), self.axis(1), self.axis(2)];
        let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
        let mut coords = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    coords.push([axes[0][i], axes[1][j], axes[2][k]]);
                }
            }
        }
        let mut cells = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let h = [
                        id(i, j, k),
                        id(i + 1, j, k),
                        id(i + 1, j + 1, k),
                        id(i, j + 1, k),
                        id(i, j, k + 1),
                        id(i + 1, j, k + 1),
                        id(i + 1, j + 1, k + 1),
                        id(i, j + 1, k + 1),
                    ];
                    match self.shape {
                        BoxCells::Hex => cells.push(Cell::new(CellKind::Hex, &h)),
                        BoxCells::Tet => {
                            // Six paths from corner 0 to corner 6, one tet each.
                            for t in [
                                [0, 1, 2, 6],
                                [0, 2, 3, 6],
                                [0, 3, 7, 6],
                                [0, 7, 4, 6],
                                [0, 4, 5, 6],
                                [0, 5, 1, 6],
                            ] {
                                cells.push(Cell::new(
                                    CellKind::Tet,
                                    &[h[t[0]], h[t[1]], h[t[2]], h[t[3]]],
                                ));
                            }
                        }
                    }
                }
            }
        }
        // Tets from the table above are negatively oriented for half the paths: fix orientation.
        for c in &mut cells {
            if c.kind == CellKind::Tet {
                let x = |l: usize| coords[c.nodes[l] as usize];
                let (a, b, d) = (sub(x(1), x(0)), sub(x(2), x(0)), sub(x(3), x(0)));
                let det = a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0])
                    + a[2] * (b[0] * d[1] - b[1] * d[0]);
                if det < 0.0 {
                    c.nodes.swap(1, 2);
                }
            }
        }
        // Boundary faces: cell faces whose nodes all lie on one side of the box.
        let logical = |v: u32| {
            let v = v as usize;
            [v % (nx + 1), (v / (nx + 1)) % (ny + 1), v / ((nx + 1) * (ny + 1))]
        };
        let mut faces = Vec::new();
        for c in &cells {
            for lf in c.kind.faces() {
                let nodes: Vec<u32> = lf.iter().map(|&l| c.nodes[l]).collect();
                for d in 0..3 {
                    for (side, end) in [(0usize, 0usize), (1, self.cells[d])] {
                        if nodes.iter().all(|&v| logical(v)[d] == end) {
                            faces.push(TaggedFace {
                                patch: (2 * d + side) as u32,
                                nodes: nodes.clone(),
                            });
                        }
                    }
                }
            }
        }
        Ok(RawMesh {
            coords,
            cells,
            faces,
            patch_names: FACE_NAMES.iter().map(|s| s.to_string()).collect(),
            origin: "box mesh".to_string(),
        })
    }
}
