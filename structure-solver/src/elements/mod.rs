//! Finite elements (DESIGN §6): one corotated frame shared by the shells and beams
//! (`corotation`), the local small-strain elements it carries (`mitc4`, `dkt`, `beam`; J2
//! shells integrated through the thickness in `layered`), the total-Lagrangian tetrahedron
//! `tet4`, the explicit one-point shells `bt4` (quadrilateral) and `blt3` (triangle) with
//! the node phase of their threaded loops (`incidence`), and the element container the
//! assembly loops over.

pub mod beam;
pub mod blt3;
pub mod bt4;
pub mod corotation;
pub mod dkt;
pub mod element;
pub mod incidence;
pub mod layered;
pub mod mitc4;
pub mod rotation;
pub mod section;
pub mod tet4;

pub use element::{Element, ElementKind};
pub use section::{BeamSection, BeamYield, RotaryInertia, ShellSection, ShellYield};

/// Adds the lumped translational mass `m` and rotary inertia `i` of one shell element to each of
/// its `nodes` (six dofs per node, `mass[6n..6n + 3]` translations, `mass[6n + 3..6n + 6]`
/// rotations).
pub(crate) fn add_node_masses(mass: &mut [f64], nodes: &[u32], m: f64, i: f64) {
    for &n in nodes {
        let n = n as usize;
        for k in 0..3 {
            mass[6 * n + k] += m;
            mass[6 * n + 3 + k] += i;
        }
    }
}
