//! What both solvers and the launcher need to report a run (DESIGN §2, §7), written once. The
//! output folder, probes, checkpoints and the non-finite check are plain Rust and always built, so
//! every participant (`rigid-structure`, `piston-fluid`, foreign peers) follows the same rules;
//! HDF5/XDMF, the gmsh reader, the progress bar and `run.json` are behind the `io` feature, so
//! light participants stay free of hdf5.
//!
//! - [`outdir`]: the run folder: creation, the refuse-to-overwrite rule (`--force`), the
//!   `runs/<case>-<timestamp>` default and the names of the files in it.
//! - [`xdmf`] (`io`): `<stem>.h5` + `<stem>.xdmf` field time series (XDMF 3; ParaView, meshio).
//! - [`probes`]: `probes.csv`, `structure_probes.csv` and `lines/<name>.csv`.
//! - [`checkpoint`]: `checkpoints/<tag>/<part>.ckpt`, named arrays + metadata, checksummed;
//!   [`checkpoint::latest`] for restarts.
//! - [`finite`]: the first-NaN stop: where the first non-finite value is, and the error text.
//! - [`progress`] (`io`): the terminal progress bar (step, time, dt, steps/s, ETA).
//! - [`report`] (`io`): `run.json` (case echo, versions, counts, wall-time buckets) and the
//!   [`report::Timers`] that fill it.
//! - [`gmsh`] (`io`): the gmsh `.msh` 4.1 reader (ASCII and binary) both solvers build their meshes
//!   on, with errors naming the file and line.
//!
//! Every file a reader may open while the run goes on (`*.xdmf`, `run.json`, checkpoints, line
//! samples) is written to a temporary name and renamed into place ([`atomic`]), so a crash leaves
//! either the previous complete file or the new one, never half of one.
//!
//! A solver's output loop, in short:
//!
//! ```no_run
//! # #[cfg(not(feature = "io"))]
//! # fn main() {}
//! # #[cfg(feature = "io")]
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use interface_protocol::io::{checkpoint, finite, outdir, probes, progress, report, xdmf};
//! let out = outdir::OutputDir::create("runs/demo", outdir::Policy::from_force(false))?;
//! let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
//! let tets: Vec<u32> = vec![0, 1, 2, 3];
//! let blocks = [xdmf::CellBlock { kind: xdmf::CellKind::Tet4, connectivity: xdmf::Connectivity::U32(&tets) }];
//! let mut fields = xdmf::TimeSeriesWriter::create(out.path(), "fluid", &xdmf::Mesh { points: &points, blocks: &blocks })?;
//! let mut probe_csv = probes::ProbeWriter::fluid(out.path(), &["inlet"])?;
//! let mut bar = progress::Progress::new(1.0, false);
//! let mut timers = report::Timers::new();
//! let (mut t, dt, mut rho) = (0.0, 0.25, vec![1.0; 4]);
//! for step in 1..=4u64 {
//!     timers.time(report::bucket::RESIDUAL, || rho.iter_mut().for_each(|r| *r *= 1.01));
//!     t += dt;
//!     finite::check_finite("rho", finite::Entity::Node, t, &rho[..])?;
//!     probe_csv.write_row(t, &[rho[0], 0.0, 0.0, 0.0, 1e5])?;
//!     let f = [xdmf::Field { name: "rho", location: xdmf::Location::Node, values: xdmf::Values::Scalar(&rho) }];
//!     timers.time(report::bucket::OUTPUT, || fields.write_step(t, &f))?;
//!     probe_csv.flush()?;
//!     let mut ck = checkpoint::Checkpoint::new(step, t);
//!     ck.put("rho", rho.clone())?;
//!     ck.write(&out.checkpoints()?, &checkpoint::tag_for_step(step), "fluid")?;
//!     bar.update(step, t, dt);
//! }
//! fields.finish()?;
//! bar.finish();
//! # Ok(()) }
//! ```

pub mod atomic;
pub mod checkpoint;
pub mod finite;
pub mod outdir;
pub mod probes;

#[cfg(feature = "io")]
pub mod gmsh;
#[cfg(feature = "io")]
pub mod progress;
#[cfg(feature = "io")]
pub mod report;
#[cfg(feature = "io")]
pub mod xdmf;
