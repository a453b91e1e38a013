//! Probe time series and line samples as CSV (DESIGN §7).
//!
//! - `probes.csv`: `time,<probe>.rho,<probe>.vx,<probe>.vy,<probe>.vz,<probe>.p` per fluid probe;
//! - `structure_probes.csv`:
//!   `time,<probe>.ux,<probe>.uy,<probe>.uz,<probe>.vx,<probe>.vy,<probe>.vz`;
//! - `lines/<name>.csv`: `x,y,z,s,rho,vx,vy,vz,p,material,phi`, one row per sample point
//!   (`phi` the level set, `NaN` when the run has none: appended last, so readers by position
//!   of the first ten columns are unaffected).
//!
//! Numbers are written in Rust's shortest round-trip exponent form (`1.5e-3`), which Python,
//! numpy and pandas parse back to the same `f64`.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Components of a fluid probe, in column order.
pub const FLUID_COMPONENTS: &[&str] = &["rho", "vx", "vy", "vz", "p"];
/// Components of a structure probe, in column order.
pub const STRUCTURE_COMPONENTS: &[&str] = &["ux", "uy", "uz", "vx", "vy", "vz"];
/// Header of a line sample file.
pub const LINE_HEADER: &str = "x,y,z,s,rho,vx,vy,vz,p,material,phi";

/// A probe or line-sample file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ProbeError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: io::Error },
    #[error("probe name `{0}` must be non-empty and contain no `,`, `\"` or line break")]
    BadName(String),
    #[error("line sample name `{0}` must be non-empty and contain no `/`, `\\` or line break")]
    BadLineName(String),
    #[error(
        "{path}: a row needs {expected} values ({probes} probes x {components} components), \
         got {got}"
    )]
    RowLength { path: PathBuf, expected: usize, got: usize, probes: usize, components: usize },
    #[error("{path}: cannot continue it from t = {t:e}: {reason}")]
    Resume { path: PathBuf, t: f64, reason: String },
}

/// Refuses a probe name that would break the CSV header (empty, or holding `,`, `"` or a line
/// break); participants call it while checking a case, before any file exists.
pub fn check_probe_name(name: &str) -> Result<(), ProbeError> {
    if name.is_empty() || name.contains([',', '"', '\n', '\r']) {
        return Err(ProbeError::BadName(name.to_string()));
    }
    Ok(())
}

/// A CSV time series with a fixed header `time,<probe>.<component>,...`: rows are buffered and
/// reach the disk at [`ProbeWriter::flush`] (call it at each field output) and on drop.
pub struct ProbeWriter {
    out: BufWriter<File>,
    path: PathBuf,
    probes: usize,
    components: usize,
    line: String,
}

impl ProbeWriter {
    /// Creates `path` (truncating it) with the header for `probes` x `components`.
    pub fn create<S: AsRef<str>>(
        path: &Path,
        probes: &[S],
        components: &[&str],
    ) -> Result<Self, ProbeError> {
        Self::open(path, probes, components, None)
    }

    /// Reopens `path` for a run continued from a checkpoint at time `t` (a restart): the file
    /// must start with the header of `probes` x `components`; its rows up to `t` stay, the rows
    /// after `t` (written past the checkpoint by the run that stopped) are dropped, and new rows
    /// follow. So the continued file holds each time once, as an uninterrupted run writes it.
    pub fn resume<S: AsRef<str>>(
        path: &Path,
        probes: &[S],
        components: &[&str],
        t: f64,
    ) -> Result<Self, ProbeError> {
        Self::open(path, probes, components, Some(t))
    }

    /// [`ProbeWriter::create`], or with `keep_until` [`ProbeWriter::resume`].
    fn open<S: AsRef<str>>(
        path: &Path,
        probes: &[S],
        components: &[&str],
        keep_until: Option<f64>,
    ) -> Result<Self, ProbeError> {
        for name in probes {
            check_probe_name(name.as_ref())?;
        }
        let io_err = |source| ProbeError::Io { path: path.to_path_buf(), source };
        let mut header = String::from("time");
        for p in probes {
            for c in components {
                header.push_str(&format!(",{}.{c}", p.as_ref()));
            }
        }
        let kept = match keep_until {
            Some(t) => rows_until(path, &header, t)?,
            None => String::new(),
        };
        let mut out = BufWriter::new(File::create(path).map_err(io_err)?);
        writeln!(out, "{header}").map_err(io_err)?;
        out.write_all(kept.as_bytes()).map_err(io_err)?;
        out.flush().map_err(io_err)?;
        Ok(Self {
            out,
            path: path.to_path_buf(),
            probes: probes.len(),
            components: components.len(),
            line: String::new(),
        })
    }

    /// `probes.csv` in `dir` with [`FLUID_COMPONENTS`].
    pub fn fluid<S: AsRef<str>>(dir: &Path, probes: &[S]) -> Result<Self, ProbeError> {
        Self::create(&dir.join("probes.csv"), probes, FLUID_COMPONENTS)
    }

    /// `structure_probes.csv` in `dir` with [`STRUCTURE_COMPONENTS`].
    pub fn structure<S: AsRef<str>>(dir: &Path, probes: &[S]) -> Result<Self, ProbeError> {
        Self::create(&dir.join("structure_probes.csv"), probes, STRUCTURE_COMPONENTS)
    }

    /// [`ProbeWriter::fluid`], continued from `t` when `resume_at` says so
    /// ([`ProbeWriter::resume`]).
    pub fn fluid_from<S: AsRef<str>>(
        dir: &Path,
        probes: &[S],
        resume_at: Option<f64>,
    ) -> Result<Self, ProbeError> {
        Self::open(&dir.join("probes.csv"), probes, FLUID_COMPONENTS, resume_at)
    }

    /// [`ProbeWriter::structure`], continued from `t` when `resume_at` says so
    /// ([`ProbeWriter::resume`]).
    pub fn structure_from<S: AsRef<str>>(
        dir: &Path,
        probes: &[S],
        resume_at: Option<f64>,
    ) -> Result<Self, ProbeError> {
        Self::open(&dir.join("structure_probes.csv"), probes, STRUCTURE_COMPONENTS, resume_at)
    }

    /// Appends one row: `values` holds the components of probe 0, then probe 1, ...
    pub fn write_row(&mut self, time: f64, values: &[f64]) -> Result<(), ProbeError> {
        let expected = self.probes * self.components;
        if values.len() != expected {
            return Err(ProbeError::RowLength {
                path: self.path.clone(),
                expected,
                got: values.len(),
                probes: self.probes,
                components: self.components,
            });
        }
        self.line.clear();
        push_number(&mut self.line, time);
        for &v in values {
            self.line.push(',');
            push_number(&mut self.line, v);
        }
        self.line.push('\n');
        self.out
            .write_all(self.line.as_bytes())
            .map_err(|source| ProbeError::Io { path: self.path.clone(), source })
    }

    /// Pushes buffered rows to the file.
    pub fn flush(&mut self) -> Result<(), ProbeError> {
        self.out.flush().map_err(|source| ProbeError::Io { path: self.path.clone(), source })
    }

    /// The file written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for ProbeWriter {
    fn drop(&mut self) {
        if let Err(e) = self.out.flush() {
            tracing::warn!("{}: could not flush probe rows: {e}", self.path.display());
        }
    }
}

/// The rows of the probe file `path` whose time is at most `t`, each with its line break; the
/// file must begin with `header`. A row whose time cannot be read is an error naming its line.
fn rows_until(path: &Path, header: &str, t: f64) -> Result<String, ProbeError> {
    let fail = |reason: String| ProbeError::Resume { path: path.to_path_buf(), t, reason };
    let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
    let mut lines = text.lines();
    let found = lines.next().unwrap_or_default();
    if found != header {
        return Err(fail(format!("its header is `{found}`, the case's probes give `{header}`")));
    }
    let mut kept = String::new();
    for (i, line) in lines.enumerate() {
        let time = line.split(',').next().unwrap_or_default();
        let time: f64 =
            time.parse().map_err(|_| fail(format!("line {}: `{time}` is not a time", i + 2)))?;
        if time > t {
            break;
        }
        kept.push_str(line);
        kept.push('\n');
    }
    Ok(kept)
}

fn push_number(s: &mut String, v: f64) {
    use std::fmt::Write as _;
    write!(s, "{v:e}").expect("writing to a String cannot fail");
}

/// One point of a line sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinePoint {
    pub x: [f64; 3],
    /// Arc length along the line from its first point.
    pub s: f64,
    pub rho: f64,
    pub v: [f64; 3],
    pub p: f64,
    /// Material (fluid phase) id, or a ghost/inactive marker chosen by the solver.
    pub material: u32,
    /// Level set at the point (`NaN` when the run has none).
    pub phi: f64,
}

/// Writes `lines_dir/<name>.csv` (atomically) with [`LINE_HEADER`] and one row per point.
/// Returns the path written.
pub fn write_line_sample(
    lines_dir: &Path,
    name: &str,
    points: &[LinePoint],
) -> Result<PathBuf, ProbeError> {
    if name.is_empty() || name.contains(['/', '\\', '\n', '\r']) {
        return Err(ProbeError::BadLineName(name.to_string()));
    }
    let path = lines_dir.join(format!("{name}.csv"));
    let mut line = String::new();
    super::atomic::write_atomic(&path, |w| {
        writeln!(w, "{LINE_HEADER}")?;
        for pt in points {
            line.clear();
            let nums = [pt.x[0], pt.x[1], pt.x[2], pt.s, pt.rho, pt.v[0], pt.v[1], pt.v[2], pt.p];
            for v in nums {
                push_number(&mut line, v);
                line.push(',');
            }
            line.push_str(&pt.material.to_string());
            line.push(',');
            push_number(&mut line, pt.phi);
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        Ok(())
    })
    .map_err(|source| ProbeError::Io { path: path.clone(), source })?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Vec<Vec<f64>> {
        text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect()
    }

    #[test]
    fn a_resumed_file_keeps_the_rows_up_to_the_restart_time_once() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("structure_probes.csv");
        let mut w = ProbeWriter::structure(dir.path(), &["tip"]).unwrap();
        for k in 0..6 {
            w.write_row(k as f64 * 0.1, &[k as f64; 6]).unwrap();
        }
        drop(w);
        // Restarted at t^3 = 0.30000000000000004: rows 0..=3 stay, 4 and 5 go, new rows follow.
        let mut w = ProbeWriter::structure_from(dir.path(), &["tip"], Some(3.0 * 0.1)).unwrap();
        w.write_row(0.4, &[-4.0; 6]).unwrap();
        drop(w);
        let rows = parse(&std::fs::read_to_string(&path).unwrap());
        let times: Vec<f64> = rows.iter().map(|r| r[0]).collect();
        assert_eq!(times, [0.0, 0.1, 0.2, 3.0 * 0.1, 0.4]);
        assert_eq!(rows[3][1], 3.0);
        assert_eq!(rows[4][1], -4.0);
        // Another case's probes: the header differs, and the file is left as it was.
        let before = std::fs::read_to_string(&path).unwrap();
        let e = ProbeWriter::structure_from(dir.path(), &["root"], Some(0.2)).err().unwrap();
        let e = e.to_string();
        assert!(e.contains("structure_probes.csv") && e.contains("time,tip.ux"), "{e}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), before);
    }

    #[test]
    fn fluid_probes_header_and_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = ProbeWriter::fluid(dir.path(), &["inlet", "wall"]).unwrap();
        let rows = [
            (0.0, [1.0, 0.0, 0.0, 0.0, 1e5, 1.2, 0.1, -0.2, 0.3, 9.9e4]),
            (1.0 / 3.0, [1.0 + f64::EPSILON, 1e-300, -0.0, 5e-324, 1e300, 0.1, 0.2, 0.3, 0.4, 0.5]),
        ];
        for (t, v) in &rows {
            w.write_row(*t, v).unwrap();
        }
        w.flush().unwrap();
        let text = std::fs::read_to_string(dir.path().join("probes.csv")).unwrap();
        assert_eq!(
            text.lines().next().unwrap(),
            "time,inlet.rho,inlet.vx,inlet.vy,inlet.vz,inlet.p,wall.rho,wall.vx,wall.vy,wall.vz,wall.p"
        );
        let back = parse(&text);
        assert_eq!(back.len(), 2);
        for ((t, v), row) in rows.iter().zip(&back) {
            assert_eq!(row[0].to_bits(), t.to_bits());
            for (a, b) in v.iter().zip(&row[1..]) {
                assert_eq!(a.to_bits(), b.to_bits());
            }
        }
    }

    #[test]
    fn structure_probes_flush_on_drop_and_check_row_length() {
        let dir = tempfile::tempdir().unwrap();
        {
            let names = vec!["tip".to_string()];
            let mut w = ProbeWriter::structure(dir.path(), &names).unwrap();
            let err = w.write_row(0.0, &[1.0; 5]).unwrap_err();
            assert!(err.to_string().contains("needs 6 values"), "{err}");
            w.write_row(0.5, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
            // Not flushed yet: the header is there, the row is still buffered.
            let text = std::fs::read_to_string(w.path()).unwrap();
            assert_eq!(text, "time,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz\n");
        }
        let text = std::fs::read_to_string(dir.path().join("structure_probes.csv")).unwrap();
        assert_eq!(parse(&text), vec![vec![0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]]);
    }

    #[test]
    fn bad_probe_names_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        assert!(matches!(ProbeWriter::fluid(dir.path(), &["a,b"]), Err(ProbeError::BadName(_))));
        assert!(matches!(ProbeWriter::fluid(dir.path(), &[""]), Err(ProbeError::BadName(_))));
        assert!(check_probe_name("tip").is_ok());
        let e = check_probe_name("a\nb").unwrap_err().to_string();
        assert!(e.contains("probe name") && e.contains("line break"), "{e}");
        assert!(!dir.path().join("probes.csv").exists(), "a refused name creates no file");
    }

    #[test]
    fn line_sample_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let pts: Vec<LinePoint> = (0..5)
            .map(|i| {
                let x = i as f64 * 0.1;
                LinePoint {
                    x: [x, 0.5, 0.0],
                    s: x,
                    rho: 1.0 + x,
                    v: [x * x, 0.0, -x],
                    p: 1e5 * (1.0 - x),
                    material: i % 2,
                    phi: if i == 4 { f64::NAN } else { x - 0.25 },
                }
            })
            .collect();
        let path = write_line_sample(dir.path(), "centerline_t0.5", &pts).unwrap();
        assert_eq!(path, dir.path().join("centerline_t0.5.csv"));
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().next().unwrap(), LINE_HEADER);
        let rows = parse(&text);
        assert_eq!(rows.len(), 5);
        // No level set: `NaN`, which Rust, Python and numpy read back as NaN.
        assert!(text.lines().nth(5).unwrap().ends_with(",0,NaN"), "{text}");
        for (pt, row) in pts.iter().zip(&rows) {
            let expect = [
                pt.x[0],
                pt.x[1],
                pt.x[2],
                pt.s,
                pt.rho,
                pt.v[0],
                pt.v[1],
                pt.v[2],
                pt.p,
                pt.material as f64,
                pt.phi,
            ];
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(row), bits(&expect), "{row:?} vs {expect:?}");
        }
        assert!(write_line_sample(dir.path(), "../x", &pts).is_err());
    }
}
