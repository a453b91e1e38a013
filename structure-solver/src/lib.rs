//! The structure side of FIVER: a nonlinear finite-element solver for shells, beams, solids and
//! rigid parts with large displacements and rotations (DESIGN §6), explicit and implicit in time.
//!
//! Modules: `mesh` (generators, gmsh reader, sets) -> `material` (elastic, J2) -> `elements`
//! (corotational shells, beams, tets, rigid) -> `assembly` (a `Model` for the integrators) ->
//! `time` (central difference, implicit midpoint, Newmark), `statics`, `modal`, sharing the
//! free-dof sparse solve of `linsolve`. Must not touch: the fluid, the IPC transport (coupling
//! goes through `interface-protocol` endpoints).
#![deny(unsafe_op_in_unsafe_fn)]

pub mod assembly;
pub mod bench;
pub mod couple;
pub mod elements;
pub mod linsolve;
pub mod material;
pub mod mesh;
pub mod modal;
pub mod model;
pub mod output;
pub mod restart;
pub mod rigid;
pub mod run;
pub mod statics;
pub mod time;
