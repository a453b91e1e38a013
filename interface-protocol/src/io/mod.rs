//! What both solvers and the launcher need to report a run (DESIGN §2, §7), written once, behind
//! the `io` feature so light participants (`rigid-structure`, foreign peers) stay small.
//!
//! | module       | owns                                                                        |
//! |--------------|-----------------------------------------------------------------------------|
//! | [`outdir`]   | the run folder: creation, the refuse-to-overwrite rule (`--force`), the    |
//! |              | `runs/<case>-<timestamp>` default and the names of every file in it         |
//! | [`xdmf`]     | `<stem>.h5` + `<stem>.xdmf` time series (XDMF 3, ParaView / meshio)         |
//! | [`probes`]   | `probes.csv`, `structure_probes.csv` and `lines/<name>.csv`                 |
//! | [`checkpoint`] | `checkpoints/<tag>/<part>.ckpt`: named arrays + metadata, checksummed     |
//! | [`finite`]   | the first-NaN stop: where the first non-finite value is and the error text  |
//! | [`progress`] | the terminal progress bar (step, time, dt, steps/s, ETA)                    |
//! | [`report`]   | `run.json`: case echo, versions, counts, wall-time buckets ([`report::Timers`]) |
//!
//! Every file a reader may open while the run goes on (`*.xdmf`, `run.json`, checkpoints, line
//! samples) is written to a temporary name and renamed into place ([`atomic`]), so a crash leaves
//! either the previous complete file or the new one, never half of one.

pub mod atomic;
pub mod checkpoint;
pub mod finite;
pub mod outdir;
pub mod probes;
pub mod progress;
pub mod report;
pub mod xdmf;
