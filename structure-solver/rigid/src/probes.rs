//! `structure_probes.csv` (DESIGN §7): `time,<probe>.ux,<probe>.uy,<probe>.uz,<probe>.vx,
//! <probe>.vy,<probe>.vz`, the displacement and velocity of the body's reference point.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// The probe file, one row per written time.
pub struct Probes {
    out: BufWriter<File>,
}

impl Probes {
    /// Creates `dir/structure_probes.csv` with its header.
    pub fn create(dir: &Path, probe: &str) -> std::io::Result<Probes> {
        std::fs::create_dir_all(dir)?;
        let path = dir.join("structure_probes.csv");
        let mut out = BufWriter::new(File::create(&path)?);
        write!(out, "time")?;
        for c in ["ux", "uy", "uz", "vx", "vy", "vz"] {
            write!(out, ",{probe}.{c}")?;
        }
        writeln!(out)?;
        Ok(Probes { out })
    }

    /// Appends the translation `u`, `v` of the reference point at `t`.
    pub fn row(&mut self, t: f64, u: [f64; 3], v: [f64; 3]) -> std::io::Result<()> {
        write!(self.out, "{t:.17e}")?;
        for x in u.iter().chain(&v) {
            write!(self.out, ",{x:.17e}")?;
        }
        writeln!(self.out)
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}
