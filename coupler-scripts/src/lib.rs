//! The `fsi` launcher: reads a case, starts the fluid and structure participants as children,
//! checks their handshake, drives the coupling scheme command by command and watches the
//! children so that nothing hangs and nothing is left behind.
//!
//! Owns: the scheme's command sequence, process supervision, the command line, `run.json`, plots.
//! Must not touch: physics (the participants hold it) or the wire format (`interface-protocol`).
#![deny(unsafe_op_in_unsafe_fn)]

pub mod check;
pub mod plot;
pub mod restart;
pub mod run;
pub mod scheme;
pub mod supervise;
