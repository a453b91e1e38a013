//! Finite elements (DESIGN §6): one corotated frame shared by the shells and beams
//! (`corotation`), the local small-strain elements it carries (`mitc4`, `dkt`, `beam`; J2
//! shells integrated through the thickness in `layered`), the total-Lagrangian tetrahedron
//! `tet4`, the explicit one-point shells `bt4` (quadrilateral) and `blt3` (triangle), and the element container the assembly loops
//! over.

pub mod beam;
pub mod blt3;
pub mod bt4;
pub mod corotation;
pub mod dkt;
pub mod element;
pub mod layered;
pub mod mitc4;
pub mod rotation;
pub mod section;
pub mod tet4;

pub use element::{Element, ElementKind};
pub use section::{BeamSection, BeamYield, RotaryInertia, ShellSection, ShellYield};
