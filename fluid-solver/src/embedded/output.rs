//! Field output of the embedded boundary (DESIGN §7): what `fluid.xdmf` shows of it at the mesh
//! nodes, and the surface itself as a second time series (`surface.h5` + `surface.xdmf`).
//!
//! On the fluid mesh, at every output time:
//! - `status`: each node's [`NodeStatus`] as its enum value, `0` active, `1` occluded (within
//!   the occlusion tolerance of the surface), `2` inactive (inside the structure);
//! - `p_wall`: the Alg. 5.1 star pressure `p*` of the cut edges put on the nodes: at an active
//!   node, the mean of the `p*` of its own side over the cut edges it is an end of; `NaN` at every
//!   other node (no cut edge, or not active).
//!
//! The surface series holds the surface's triangles and quads (a quad is the structure element
//! the fluid split into two triangles, merged back) with the nodal positions of each output time
//! written with that step (a moving mesh: [`TimeSeriesWriter::write_moved_step`]), and at the
//! surface nodes:
//! - `velocity`: the nodal velocity at that time;
//! - `p_plus`, `p_minus`: the cut-edge `p*` on the side the structure's normal `n_E` points into
//!   (`+`) and on the other side (`-`), the end of each cut edge given its side by the orientation
//!   contract ([`wall_normal_from_i`]), carried to the corners of the triangle hit with the
//!   barycentric coordinates of the intersection point as weights: `Σ w p* / Σ w` at each node,
//!   `NaN` at nodes no cut edge of that side reaches. The triangle a cut edge records is the one
//!   nearest its end `i`, so the `p*` of `j` is carried to it only when `i` is inside the structure
//!   (inactive) or active on the other side: not when both ends lie on one side (an edge through
//!   a body's corner, cut twice, or round an open shell's rim) nor when `i` is occluded (the
//!   triangle at `i` need not be the wall `j` sees); an edge lying in the plane of its triangle
//!   (`|n_E · d̂_ij|` below [`PARALLEL_TOLERANCE`]) is not carried at all.
//!
//! A change of topology (a crack: new triangles, new nodes) starts a new series,
//! `surface_v<version>.h5` + `.xdmf`, at the first output time after it.

use super::riemann_fs::{wall_normal_from_i, PARALLEL_TOLERANCE};
use super::status::NodeStatus;
use super::tracker::Tracker;
use super::Surface;
use crate::mesh::geometry::{dot, norm, sub};
use crate::mesh::Mesh;
use interface_protocol::io::xdmf::{
    self, CellBlock, CellKind, Connectivity, Field, Location, TimeSeriesWriter, Values,
};
use std::path::{Path, PathBuf};

/// Each node's status as a field value (the enum value of [`NodeStatus`]).
pub fn node_status(tracker: &Tracker) -> Vec<f64> {
    tracker.sides.status.iter().map(|&s| f64::from(s as u8)).collect()
}

/// `p_wall` (module doc): at each active node the mean `p*` of its side over its cut edges, `NaN`
/// elsewhere.
pub fn wall_pressure_at_nodes(mesh: &Mesh, tracker: &Tracker) -> Vec<f64> {
    let n = mesh.n_nodes();
    let (mut sum, mut count) = (vec![0.0; n], vec![0u32; n]);
    for (cut, ps) in tracker.cuts.cuts.iter().zip(&tracker.p_star) {
        let [i, j] = mesh.edges[cut.edge as usize].map(|v| v as usize);
        for (node, p) in [(i, ps[0]), (j, ps[1])] {
            if tracker.active[node] {
                sum[node] += p;
                count[node] += 1;
            }
        }
    }
    sum.iter().zip(&count).map(|(&s, &c)| if c > 0 { s / f64::from(c) } else { f64::NAN }).collect()
}

/// The fluid-mesh fields of the module doc, `(status, p_wall)`.
pub fn mesh_fields(mesh: &Mesh, tracker: &Tracker) -> (Vec<f64>, Vec<f64>) {
    (node_status(tracker), wall_pressure_at_nodes(mesh, tracker))
}

/// `(p_plus, p_minus)` at the surface nodes (module doc).
pub fn side_pressures(mesh: &Mesh, tracker: &Tracker) -> (Vec<f64>, Vec<f64>) {
    let surface = &tracker.surface;
    let n = surface.n_nodes();
    // Per side (0: +, 1: -): Σ w p and Σ w at each surface node.
    let mut acc = [vec![[0.0; 2]; n], vec![[0.0; 2]; n]];
    for (cut, ps) in tracker.cuts.cuts.iter().zip(&tracker.p_star) {
        let e = cut.edge as usize;
        let [i, j] = mesh.edges[e].map(|v| v as usize);
        let d_ij = sub(mesh.coords[j], mesh.coords[i]);
        if dot(cut.normal, d_ij).abs() < PARALLEL_TOLERANCE * norm(d_ij) {
            // An edge in the plane of the triangle: neither end has a side of it.
            continue;
        }
        let from_i = wall_normal_from_i(cut.normal, d_ij, mesh.edge_normals[e]);
        // The wall lies ahead of `i` along `from_i`: `i` is on the `+` side when that is `-n_E`.
        let i_plus = dot(from_i, cut.normal) < 0.0;
        // The triangle recorded is the wall of `i`; it is that of `j` only across a crossing.
        let j_too = match tracker.sides.status[i] {
            NodeStatus::Active => tracker.sides.side[i] != tracker.sides.side[j],
            NodeStatus::Inactive => true,
            NodeStatus::Occluded => false,
        };
        let p_j = if j_too { ps[1] } else { f64::NAN };
        let by_side = if i_plus { [ps[0], p_j] } else { [p_j, ps[0]] };
        let corners = surface.triangles[cut.triangle as usize];
        for (side, p) in by_side.into_iter().enumerate() {
            if !p.is_finite() {
                continue;
            }
            for (node, w) in corners.iter().zip(cut.bary) {
                let a = &mut acc[side][*node as usize];
                a[0] += w * p;
                a[1] += w;
            }
        }
    }
    let [plus, minus] =
        acc.map(|a| a.iter().map(|&[s, w]| if w > 0.0 { s / w } else { f64::NAN }).collect());
    (plus, minus)
}

/// The surface's cells: its triangles, the pairs split from one quad merged back into it.
fn cells(surface: &Surface) -> (Vec<u32>, Vec<u32>) {
    let (mut tris, mut quads) = (Vec::new(), Vec::new());
    let t = &surface.triangles;
    let mut k = 0;
    while k < t.len() {
        let [a, b, c] = t[k];
        let pair = k + 1 < t.len() && surface.element_of[k + 1] == surface.element_of[k];
        if pair && t[k + 1][0] == a && t[k + 1][1] == c {
            quads.extend_from_slice(&[a, b, c, t[k + 1][2]]);
            k += 2;
        } else {
            tris.extend_from_slice(&[a, b, c]);
            k += 1;
        }
    }
    (tris, quads)
}

/// `surface.h5` + `surface.xdmf` (module doc).
pub struct SurfaceSeries {
    dir: PathBuf,
    writer: TimeSeriesWriter,
    /// The topology version and node count the open series was made for.
    version: u64,
    nodes: usize,
}

impl SurfaceSeries {
    /// Opens the series of `surface` in `dir` (`surface` for its first topology).
    pub fn create(dir: &Path, surface: &Surface) -> Result<Self, xdmf::XdmfError> {
        Self::open(dir, "surface", surface)
    }

    fn open(dir: &Path, stem: &str, surface: &Surface) -> Result<Self, xdmf::XdmfError> {
        let (tris, quads) = cells(surface);
        let blocks: Vec<CellBlock> = [(CellKind::Tri3, &tris), (CellKind::Quad4, &quads)]
            .into_iter()
            .filter(|(_, c)| !c.is_empty())
            .map(|(kind, c)| CellBlock { kind, connectivity: Connectivity::U32(c) })
            .collect();
        let mesh = xdmf::Mesh { points: &surface.x_b, blocks: &blocks };
        Ok(SurfaceSeries {
            dir: dir.to_path_buf(),
            writer: TimeSeriesWriter::create(dir, stem, &mesh)?,
            version: surface.topology_version,
            nodes: surface.n_nodes(),
        })
    }

    /// Writes the surface of `tracker` at its current time `time`: positions, velocities and the
    /// two sides' `p*` (starting a new series after a change of topology).
    pub fn write(
        &mut self,
        time: f64,
        mesh: &Mesh,
        tracker: &Tracker,
    ) -> Result<(), xdmf::XdmfError> {
        let surface = &tracker.surface;
        if surface.topology_version != self.version || surface.n_nodes() != self.nodes {
            let stem = format!("surface_v{}", surface.topology_version);
            let next = Self::open(&self.dir, &stem, surface)?;
            std::mem::replace(self, next).finish()?;
        }
        let (p_plus, p_minus) = side_pressures(mesh, tracker);
        let fields = [
            Field {
                name: "velocity",
                location: Location::Node,
                values: Values::Vector(&surface.v_b),
            },
            Field { name: "p_plus", location: Location::Node, values: Values::Scalar(&p_plus) },
            Field { name: "p_minus", location: Location::Node, values: Values::Scalar(&p_minus) },
        ];
        self.writer.write_moved_step(time, &surface.x_b, &fields)
    }

    /// Flushes and closes the files.
    pub fn finish(self) -> Result<(), xdmf::XdmfError> {
        self.writer.finish()
    }
}
