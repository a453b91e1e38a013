//! The fluid side of FIVER: a vertex-centred, edge-based finite-volume solver of the compressible
//! Euler equations on arbitrary non-body-fitted grids (thesis Ch. 2-3), growing towards the
//! embedded boundary of Ch. 4-5.
//!
//! Modules follow the discretisation: `eos` -> `mesh` (geometry and connectivity only, never
//! solver state) -> `riemann`, `flux`, `reconstruct`, `bc` -> `state`, `initial` ->
//! `special_edges`, `two_phase` -> `semidiscretization` (the residual, its `error`s) -> `time` ->
//! `levelset` (the moving interface between two fluids) -> `setup`
//! (everything before the first step, with `memory`) -> `solver` (the run loop) with `output`,
//! `probes` -> `couple` (the coupling participant) and `check` (`fluid-solver check`). Must not touch: the structure, the IPC
//! transport (it talks to the structure only through `interface-protocol` endpoints).
#![deny(unsafe_op_in_unsafe_fn)]

pub mod bc;
pub mod bench;
pub mod bench_bubble;
pub mod bench_embedded;
pub mod check;
pub mod couple;
pub mod embedded;
pub mod eos;
pub mod error;
pub mod flux;
pub mod initial;
pub mod levelset;
pub mod memory;
pub mod mesh;
pub mod output;
pub mod prefetch;
pub mod probes;
pub mod reconstruct;
pub mod riemann;
mod run_report;
pub mod semidiscretization;
pub mod setup;
pub mod solver;
pub mod special_edges;
pub mod state;
pub mod symmetry;
pub mod time;
pub mod two_phase;
