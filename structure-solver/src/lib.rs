//! The structure side of FIVER: a nonlinear finite-element solver for shells, beams, solids and
//! rigid parts with large displacements and rotations (DESIGN §6), explicit and implicit in time.
//!
//! Modules: `mesh` (generators, gmsh reader, sets, the validity pass) -> `material` (elastic,
//! J2) -> `elements` (corotational shells, beams, tets, rigid) -> `assembly` (a `Model` for the
//! integrators) -> `time` (central difference, implicit midpoint, Newmark), `statics`, `modal`,
//! sharing the free-dof sparse solve of `linsolve`. A case becomes a model in `case_mesh` and
//! `build`; `prepare` does all a run alone does before its first step (shared by `run` and
//! `check`), `couple` runs the coupled participant; `state_check` is the every-step finite
//! check of both. Must not touch: the fluid, the IPC transport (coupling
//! goes through `interface-protocol` endpoints).
#![deny(unsafe_op_in_unsafe_fn)]

pub mod assembly;
pub mod bench;
pub mod bench_blt3;
pub mod bench_c;
pub mod bench_implicit;
pub mod build;
pub mod case_mesh;
pub mod check;
pub mod couple;
pub mod elements;
pub mod linsolve;
pub mod material;
pub mod mesh;
pub mod modal;
pub mod model;
pub mod output;
pub mod prepare;
pub mod restart;
pub mod rigid;
pub mod run;
pub mod state_check;
pub mod statics;
pub mod time;
pub mod wet;
