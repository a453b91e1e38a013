//! The embedded boundary (thesis Ch. 4-5, DESIGN §5.1): a structure surface that the fluid mesh
//! does not fit, seen by the fluid only through the edges it cuts.
//!
//! One file per step of the path, in the order a step runs them: [`surface`] (the triangles and
//! their motion on the Hermite path of DESIGN §4) -> `bvh` (boxes swept over the step) ->
//! `predicates` (exact orientation tests) -> `intersect` (Alg. 4.1 and 4.2: the cut edges) ->
//! `status` (active, occluded and inactive nodes, sides, swept nodes) -> `riemann_fs` (Alg. 5.1
//! at every cut edge) -> `loads` (Alg. 5.3 and 5.4). The residual sees all of it through a
//! read-only view with the stage time; `Semidiscretization` never owns the surface. What a run
//! carries from step to step goes into its checkpoints ([`checkpoint`]); what it shows in the
//! field output is in [`output`].

pub mod adjacency;
pub mod advance;
pub mod bvh;
pub mod case;
pub mod checkpoint;
#[cfg(test)]
mod checkpoint_tests;
pub mod fill;
pub mod generate;
pub mod intersect;
pub mod level_set;
pub mod loads;
pub mod motion;
pub mod output;
pub mod predicates;
pub mod read;
pub mod riemann_fs;
pub mod sample;
pub mod side_fluid;
pub mod status;
pub mod step;
pub mod surface;
pub mod swept;
#[cfg(test)]
pub(crate) mod test_cuts;
#[cfg(test)]
mod tests;
pub mod tracker;

pub use surface::Surface;

/// One intersection of a fluid edge with the surface: the output of the tracking algorithms
/// (thesis Alg. 4.1 and 4.2) that the fluxes (Alg. 5.1) and the loads (Alg. 5.3, 5.4) read.
///
/// The cut edges of a mesh are kept sorted by `edge`, one record per cut edge (the intersection
/// nearest to node `i` when the edge crosses the surface more than once).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutEdge {
    /// Index into `Mesh::edges` of the edge `(i, j)`, `i < j`.
    pub edge: u32,
    /// Position of the intersection along the edge: `x = x_i + α (x_j - x_i)`, `α ∈ [0, 1]`.
    pub alpha: f64,
    /// The surface triangle hit ([`Surface::triangles`]).
    pub triangle: u32,
    /// Barycentric coordinates of the intersection point in that triangle (sum 1).
    pub bary: [f64; 3],
    /// Unit normal `n_E` of the triangle in the structure's winding (not oriented by the edge).
    pub normal: [f64; 3],
}
