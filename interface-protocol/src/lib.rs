//! The contract between the FSI solvers: the `#[repr(C)]` messages that cross iceoryx2 shared
//! memory, the endpoints that hide iceoryx2 from solver code, the coupling formulas of the
//! staggered schemes, the case-file parser shared by all executables and the run outputs
//! ([`io`]: the output folder, probes, checkpoints everywhere; HDF5/XDMF, progress bar and
//! `run.json` with feature `io`).
//!
//! Owns: message layout, service names, handshake, liveness, case parsing, coupling formulas.
//! Must not touch: fluid or structure physics; it stays light enough for foreign peers and the
//! rigid-body solver.
#![deny(unsafe_op_in_unsafe_fn)]

pub mod bench;
pub mod case;
pub mod coupling;
pub mod endpoint;
pub mod handshake;
pub mod liveness;
pub mod messages;
pub mod participant;
pub mod resources;
pub mod services;
pub mod shm;

#[cfg(feature = "cli")]
pub mod cli;
pub mod io;
