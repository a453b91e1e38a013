//! Grids: geometry and connectivity only, never solver state.
//!
//! A [`RawMesh`] (nodes, volume cells, named boundary faces) comes from the box mesher
//! ([`boxmesh`]), the ball-octant mesher ([`octant`]) or a gmsh file ([`gmsh`]);
//! [`Mesh::build`] renumbers its nodes (reverse Cuthill-McKee), builds the edge list sorted by
//! `(i, j)` with `i < j`, and the median-dual control volumes of thesis §3.3.1 (Eq. 3.3-3.4):
//! dual volumes `|C_i|`, edge area normals `ν_ij = ∫_{∂C_i ∩ ∂C_j} n` oriented from `i` to `j`,
//! and per named boundary the dual boundary area vector of each of its nodes (outward). Closure
//! holds to round-off for every node: `Σ_{j} ±ν_ij + Σ_boundaries n_i = 0`. The edges are cut
//! into the blocks of [`blocks`] for the parallel edge loops; nothing else is kept per edge or
//! per node-edge pair (no node-to-edge lists), so a mesh costs about 470 bytes per node on tets,
//! cells included.
//!
//! MPI (DESIGN §10): a partition will carry its owned nodes first and ghost nodes after them in
//! this same structure (`n_owned` below the node count); edges between two ghosts are dropped and
//! the residual is accumulated for owned nodes only.

pub mod blocks;
pub mod boxmesh;
pub mod cell;
mod dual;
pub mod geometry;
pub mod gmsh;
pub mod locate;
pub mod octant;
pub mod renumber;

pub use blocks::EdgeBlocks;
pub use cell::{Cell, CellKind};

/// A boundary face of a raw mesh: the index of its named boundary and its nodes (3 or 4).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TaggedFace {
    pub patch: u32,
    pub nodes: Vec<u32>,
}

/// A mesh before the dual is built: what a mesher or a mesh file provides.
#[derive(Debug, Clone, Default)]
pub struct RawMesh {
    pub coords: Vec<[f64; 3]>,
    pub cells: Vec<Cell>,
    pub faces: Vec<TaggedFace>,
    /// Names of the boundaries; `TaggedFace::patch` indexes this.
    pub patch_names: Vec<String>,
    /// Where the mesh came from, for error messages (a file path or "box mesh").
    pub origin: String,
}

/// A named part of the boundary: its nodes (ascending) and each node's outward dual boundary
/// area vector.
#[derive(Debug, Clone)]
pub struct Boundary {
    pub name: String,
    pub nodes: Vec<u32>,
    pub normals: Vec<[f64; 3]>,
}

/// The median-dual finite-volume mesh (thesis §3.3.1).
#[derive(Debug, Clone)]
pub struct Mesh {
    /// Node coordinates, in the renumbered order.
    pub coords: Vec<[f64; 3]>,
    /// For each node, its number in the raw mesh it was built from.
    pub original_ids: Vec<u32>,
    /// Volume cells with renumbered nodes.
    pub cells: Vec<Cell>,
    /// Dual control-volume measures `|C_i|`.
    pub volumes: Vec<f64>,
    /// Edges `(i, j)`, `i < j`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// Edge area normals `ν_ij`, oriented from `i` to `j`.
    pub edge_normals: Vec<[f64; 3]>,
    /// Surface area of each dual cell: `Σ_j |ν_ij| + Σ_boundaries |n_i|` (for time steps).
    pub dual_areas: Vec<f64>,
    /// The edges cut into blocks for the parallel edge loops ([`blocks`]).
    pub blocks: EdgeBlocks,
    /// Named boundaries.
    pub boundaries: Vec<Boundary>,
}

/// Mesh errors: bad input, named.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("{origin}: cell {cell} ({kind}) is inverted or has zero volume (volume {volume:e}); its nodes must follow gmsh's ordering with a positive orientation")]
    BadCell { origin: String, cell: usize, kind: &'static str, volume: f64 },
    #[error("{origin}: cell {cell} ({kind}) lists node {node} twice: its corners must be distinct nodes")]
    RepeatedNode { origin: String, cell: usize, kind: &'static str, node: u32 },
    #[error("{origin}: cell {cell} refers to node {node}, but the mesh has {n_nodes} nodes")]
    BadNode { origin: String, cell: usize, node: u32, n_nodes: usize },
    #[error("{origin}: boundary face {nodes:?} of `{patch}` is not a face of any volume cell")]
    OrphanFace { origin: String, patch: String, nodes: Vec<u32> },
    #[error("{origin}: the dual cell of node {node} at {position:?} is not closed (mismatch {mismatch:e}): part of the boundary near it is not in any named boundary (physical group)")]
    OpenBoundary { origin: String, node: usize, position: [f64; 3], mismatch: f64 },
    #[error("unknown boundary `{name}`; the mesh has: {known}")]
    UnknownBoundary { name: String, known: String },
    #[error("{0}")]
    Input(String),
}

impl Mesh {
    /// Builds the dual mesh: compacts unused nodes, renumbers by reverse Cuthill-McKee, computes
    /// edges, dual volumes, edge normals and boundary normals, and checks closure.
    pub fn build(raw: RawMesh) -> Result<Mesh, MeshError> {
        dual::build(raw)
    }

    pub fn n_nodes(&self) -> usize {
        self.coords.len()
    }

    pub fn n_edges(&self) -> usize {
        self.edges.len()
    }

    /// Sum of the dual volumes.
    pub fn total_volume(&self) -> f64 {
        self.volumes.iter().sum()
    }

    /// The boundary of this name, or an error listing the known names.
    pub fn boundary(&self, name: &str) -> Result<&Boundary, MeshError> {
        self.boundaries.iter().find(|b| b.name == name).ok_or_else(|| MeshError::UnknownBoundary {
            name: name.to_string(),
            known: self.boundary_names().join(", "),
        })
    }

    /// Names of all boundaries.
    pub fn boundary_names(&self) -> Vec<String> {
        self.boundaries.iter().map(|b| b.name.clone()).collect()
    }

    /// Closure defect of every node: `Σ_j ±ν_ij + Σ n_i^boundary` (zero for a closed dual cell).
    pub fn closure_defects(&self) -> Vec<[f64; 3]> {
        let mut s = vec![[0.0; 3]; self.n_nodes()];
        for (&[i, j], &nu) in self.edges.iter().zip(&self.edge_normals) {
            s[i as usize] = geometry::add(s[i as usize], nu);
            s[j as usize] = geometry::sub(s[j as usize], nu);
        }
        for b in &self.boundaries {
            for (&i, &n) in b.nodes.iter().zip(&b.normals) {
                s[i as usize] = geometry::add(s[i as usize], n);
            }
        }
        s
    }

    /// The corners `(lo, hi)` of the axis-aligned box around the nodes.
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        bounding_box(&self.coords)
    }

    /// Shortest edge length at each node.
    pub fn min_edge_length(&self) -> Vec<f64> {
        let mut h = vec![f64::INFINITY; self.n_nodes()];
        for &[i, j] in &self.edges {
            let l = geometry::norm(geometry::sub(self.coords[j as usize], self.coords[i as usize]));
            h[i as usize] = h[i as usize].min(l);
            h[j as usize] = h[j as usize].min(l);
        }
        h
    }

    /// Memory of the mesh arrays in bytes (their lengths, not their capacities).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.coords[..])
            + size_of_val(&self.original_ids[..])
            + size_of_val(&self.cells[..])
            + size_of_val(&self.volumes[..])
            + size_of_val(&self.edges[..])
            + size_of_val(&self.edge_normals[..])
            + size_of_val(&self.dual_areas[..])
            + self.blocks.memory_bytes()
            + self
                .boundaries
                .iter()
                .map(|b| size_of_val(&b.nodes[..]) + size_of_val(&b.normals[..]) + b.name.len())
                .sum::<usize>()
    }
}

/// The corners `(lo, hi)` of the axis-aligned box around `points`.
fn bounding_box(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (lo, hi)
}

/// Moves each node by a random vector of length up to `fraction` times its shortest edge,
/// keeping nodes on the planes `x, y, z = min/max` of the bounding box on them (for making
/// "unstructured" test meshes from box meshes). Deterministic for a seed.
pub fn perturb(raw: &mut RawMesh, fraction: f64, seed: u64) {
    let (lo, hi) = bounding_box(&raw.coords);
    let mut h = vec![f64::INFINITY; raw.coords.len()];
    for c in &raw.cells {
        for &[a, b] in c.kind.edges() {
            let (i, j) = (c.nodes[a] as usize, c.nodes[b] as usize);
            let l = geometry::norm(geometry::sub(raw.coords[i], raw.coords[j]));
            h[i] = h[i].min(l);
            h[j] = h[j].min(l);
        }
    }
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut uniform = move || {
        // xorshift64*
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    };
    for (i, p) in raw.coords.iter_mut().enumerate() {
        let tol = 1e-12 * (1.0 + h[i]);
        // A random direction inside the unit ball, scaled.
        let v = loop {
            let v = [2.0 * uniform() - 1.0, 2.0 * uniform() - 1.0, 2.0 * uniform() - 1.0];
            if geometry::dot(v, v) <= 1.0 {
                break v;
            }
        };
        for d in 0..3 {
            if (p[d] - lo[d]).abs() > tol && (p[d] - hi[d]).abs() > tol {
                p[d] += fraction * h[i] * v[d];
            }
        }
    }
}
