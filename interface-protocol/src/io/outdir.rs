//! The run folder (DESIGN §7): created once, never silently mixed with an older run, and the one
//! place that names the files in it.
//!
//! Standalone, a solver or the launcher calls [`OutputDir::create`] with [`Policy::Fresh`] (or
//! [`Policy::Overwrite`] under `--force`); coupled, the launcher creates the folder and both
//! solvers attach to it with [`Policy::Existing`].

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

/// Files and folders a run writes into its output folder; `--force` removes these and only these.
pub const RUN_OUTPUTS: &[&str] = &[
    "fluid.h5",
    "fluid.xdmf",
    "structure.h5",
    "structure.xdmf",
    "probes.csv",
    "structure_probes.csv",
    "lines",
    "run.json",
    "checkpoints",
];

/// What to do when the output folder already exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Policy {
    /// Create it; refuse if it exists and is not empty.
    Fresh,
    /// Create it; if it exists, remove the previous run's outputs ([`RUN_OUTPUTS`]) first,
    /// `checkpoints/` included: never combine it with a restart from the same folder.
    Overwrite,
    /// It must exist already (the launcher made it); write into it as is.
    Existing,
}

impl Policy {
    /// The rule of a run alone, [`Policy::from_force`], with one refinement: a restart from
    /// the output folder itself under `--force` continues that run in place (`Existing`: its
    /// checkpoints stay, its other outputs are written anew from the restart time), and without
    /// `--force` is refused like any folder holding a run. Read the checkpoint first.
    pub fn alone(force: bool, restart_from: Option<&Path>, out: &Path) -> Self {
        let same = |from: &Path| matches!((from.canonicalize(), out.canonicalize()), (Ok(a), Ok(b)) if a == b);
        match restart_from {
            Some(from) if force && same(from) => Policy::Existing,
            _ => Policy::from_force(force),
        }
    }

    /// `Overwrite` when the user passed `--force`, `Fresh` otherwise.
    pub fn from_force(force: bool) -> Self {
        if force {
            Policy::Overwrite
        } else {
            Policy::Fresh
        }
    }
}

/// Why the output folder cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum OutDirError {
    #[error(
        "output folder `{dir}` already exists and is not empty (it holds {}); pass --force to \
         overwrite the previous run's files, or choose another folder with --out",
        list(.entries)
    )]
    NotEmpty { dir: PathBuf, entries: Vec<String> },
    #[error("output folder `{0}` does not exist (the launcher should have created it)")]
    Missing(PathBuf),
    #[error("output path `{0}` exists and is not a folder")]
    NotADir(PathBuf),
    #[error("output folder `{dir}`: {source}")]
    Io { dir: PathBuf, source: io::Error },
}

fn list(entries: &[String]) -> String {
    const SHOWN: usize = 5;
    let mut s: Vec<String> = entries.iter().take(SHOWN).map(|e| format!("`{e}`")).collect();
    if entries.len() > SHOWN {
        s.push(format!("and {} more", entries.len() - SHOWN));
    }
    s.join(", ")
}

/// A usable run folder and the names of the files in it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputDir {
    root: PathBuf,
}

impl OutputDir {
    /// Prepares `dir` according to `policy` (see [`Policy`]).
    pub fn create(dir: impl Into<PathBuf>, policy: Policy) -> Result<Self, OutDirError> {
        let root: PathBuf = dir.into();
        let io_err = |source| OutDirError::Io { dir: root.clone(), source };
        match fs::metadata(&root) {
            Ok(m) if !m.is_dir() => return Err(OutDirError::NotADir(root)),
            Ok(_) => match policy {
                Policy::Existing => {}
                Policy::Fresh => {
                    let mut entries: Vec<String> = fs::read_dir(&root)
                        .map_err(io_err)?
                        .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
                        .collect::<Result<_, _>>()
                        .map_err(io_err)?;
                    if !entries.is_empty() {
                        entries.sort();
                        return Err(OutDirError::NotEmpty { dir: root, entries });
                    }
                }
                Policy::Overwrite => {
                    for name in RUN_OUTPUTS {
                        let p = root.join(name);
                        let removed = match fs::symlink_metadata(&p) {
                            Ok(m) if m.is_dir() => fs::remove_dir_all(&p),
                            Ok(_) => fs::remove_file(&p),
                            Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
                            Err(e) => Err(e),
                        };
                        removed.map_err(io_err)?;
                    }
                }
            },
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                if policy == Policy::Existing {
                    return Err(OutDirError::Missing(root));
                }
                fs::create_dir_all(&root).map_err(io_err)?;
            }
            Err(e) => return Err(io_err(e)),
        }
        Ok(Self { root })
    }

    /// The folder itself.
    pub fn path(&self) -> &Path {
        &self.root
    }
    /// `probes.csv` (fluid probes).
    pub fn fluid_probes(&self) -> PathBuf {
        self.root.join("probes.csv")
    }
    /// `structure_probes.csv`.
    pub fn structure_probes(&self) -> PathBuf {
        self.root.join("structure_probes.csv")
    }
    /// `lines/`, created on first use.
    pub fn lines(&self) -> io::Result<PathBuf> {
        self.subdir("lines")
    }
    /// `checkpoints/`, created on first use.
    pub fn checkpoints(&self) -> io::Result<PathBuf> {
        self.subdir("checkpoints")
    }
    /// `run.json`.
    pub fn run_json(&self) -> PathBuf {
        self.root.join("run.json")
    }

    fn subdir(&self, name: &str) -> io::Result<PathBuf> {
        let p = self.root.join(name);
        fs::create_dir_all(&p)?;
        Ok(p)
    }
}

/// The case name used in default folder names: the case file's folder for `.../<name>/case.toml`,
/// otherwise the file stem (`piston.toml` -> `piston`).
pub fn case_name(case_file: &Path) -> String {
    let stem = case_file.file_stem().map(|s| s.to_string_lossy().into_owned());
    let parent =
        case_file.parent().and_then(|p| p.file_name()).map(|s| s.to_string_lossy().into_owned());
    match (stem.as_deref(), parent) {
        (Some("case"), Some(dir)) => dir,
        (Some(s), _) => s.to_string(),
        (None, _) => "run".to_string(),
    }
}

/// `runs/<case>-<YYYYMMDD-HHMMSS>` (UTC) for the case file `case_file` at time `now`.
pub fn default_run_dir(case_file: &Path, now: SystemTime) -> PathBuf {
    Path::new("runs").join(format!("{}-{}", case_name(case_file), timestamp(now)))
}

/// `YYYYMMDD-HHMMSS` in UTC.
pub fn timestamp(now: SystemTime) -> String {
    let secs = now.duration_since(UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    let (days, rem) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    format!("{y:04}{m:02}{d:02}-{:02}{:02}{:02}", rem / 3600, rem % 3600 / 60, rem % 60)
}

/// Gregorian date of a day count since 1970-01-01 (H. Hinnant, "chrono-compatible low-level date
/// algorithms", `civil_from_days`).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn fresh_creates_nested_folder() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("runs/a");
        let out = OutputDir::create(&dir, Policy::Fresh).unwrap();
        assert!(dir.is_dir());
        assert_eq!(out.run_json(), dir.join("run.json"));
        assert_eq!(out.checkpoints().unwrap(), dir.join("checkpoints"));
        assert!(dir.join("checkpoints").is_dir());
        // An existing empty folder is fine too.
        let empty = tmp.path().join("empty");
        fs::create_dir(&empty).unwrap();
        OutputDir::create(&empty, Policy::Fresh).unwrap();
    }

    #[test]
    fn refuses_non_empty_folder_and_says_how_to_force() {
        let tmp = tempfile::tempdir().unwrap();
        fs::write(tmp.path().join("fluid.h5"), b"old").unwrap();
        let err = OutputDir::create(tmp.path(), Policy::Fresh).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, OutDirError::NotEmpty { .. }));
        assert!(
            msg.contains("--force") && msg.contains("fluid.h5") && msg.contains("--out"),
            "{msg}"
        );
        assert_eq!(fs::read(tmp.path().join("fluid.h5")).unwrap(), b"old");
    }

    #[test]
    fn overwrite_removes_run_outputs_only() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path();
        fs::write(root.join("fluid.xdmf"), b"old").unwrap();
        fs::create_dir_all(root.join("checkpoints/step_1")).unwrap();
        fs::write(root.join("checkpoints/step_1/fluid.ckpt"), b"old").unwrap();
        fs::write(root.join("notes.txt"), b"mine").unwrap();
        OutputDir::create(root, Policy::from_force(true)).unwrap();
        assert!(!root.join("fluid.xdmf").exists());
        assert!(!root.join("checkpoints").exists());
        assert_eq!(fs::read(root.join("notes.txt")).unwrap(), b"mine");
    }

    #[test]
    fn existing_requires_the_folder_and_keeps_content() {
        let tmp = tempfile::tempdir().unwrap();
        let missing = tmp.path().join("nope");
        let err = OutputDir::create(&missing, Policy::Existing).unwrap_err();
        assert!(err.to_string().contains("does not exist"), "{err}");
        fs::write(tmp.path().join("structure.h5"), b"peer").unwrap();
        OutputDir::create(tmp.path(), Policy::Existing).unwrap();
        assert!(tmp.path().join("structure.h5").exists());
        let file = tmp.path().join("structure.h5");
        assert!(matches!(OutputDir::create(&file, Policy::Fresh), Err(OutDirError::NotADir(_))));
    }

    #[test]
    fn default_name_uses_case_folder_and_utc_stamp() {
        // 2024-02-29 13:45:07 UTC = 1709214307 s.
        let t = UNIX_EPOCH + Duration::from_secs(1_709_214_307);
        assert_eq!(timestamp(t), "20240229-134507");
        assert_eq!(
            default_run_dir(Path::new("cases/piston/case.toml"), t),
            Path::new("runs/piston-20240229-134507")
        );
        assert_eq!(case_name(Path::new("shock_tube.toml")), "shock_tube");
        assert_eq!(timestamp(UNIX_EPOCH), "19700101-000000");
        // 2000-12-31 23:59:59 UTC, the last day of a leap century year.
        assert_eq!(timestamp(UNIX_EPOCH + Duration::from_secs(978_307_199)), "20001231-235959");
    }
}
