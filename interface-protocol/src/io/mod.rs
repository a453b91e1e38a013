//! What both solvers need to report a run (DESIGN §2, §7), written once: the HDF5 + XDMF time
//! series ParaView opens, probe CSV files, `run.json` pieces, the progress bar, checkpoint folders
//! and the first-non-finite stop. Behind the `io` feature so light participants stay small.
