//! `fsi run CASE --restart DIR`: the launcher's part of a coupled restart (PROTOCOL.md §4, the
//! restart sequence in [`crate::scheme`]).
//!
//! At every checkpoint, once both participants answered `Done`, the launcher writes its own part
//! `checkpoints/<tag>/launcher.ckpt` (the scheme and `coupling.dt` of the run). A checkpoint is
//! *common* when the structure's, the fluid's and the launcher's parts are all there, intact and
//! at one step; a restart continues from the newest common one ([`common_checkpoint`]), checked
//! against the case: another scheme or another `coupling.dt` would not continue the run that
//! wrote it. `coupling.t_end` may differ: that is how a run is extended.

use crate::scheme::{scheme_name, SchemeSettings};
use interface_protocol::io::checkpoint::{self, Checkpoint, Found, Search, Skipped};
use interface_protocol::messages::{capability, Hello};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The launcher's part name.
pub const PART: &str = "launcher";

/// The parts a common checkpoint holds.
const PARTS: [&str; 3] = ["structure", "fluid", PART];

/// What the launcher's part records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Meta {
    scheme: String,
    dt: f64,
}

/// Writes `checkpoints_dir/<tag>/launcher.ckpt` for the checkpoint after `step` steps at `t`.
pub fn write_part(
    checkpoints_dir: &Path,
    tag: &str,
    (step, t): (u64, f64),
    s: &SchemeSettings,
) -> Result<(), checkpoint::CheckpointError> {
    let mut ck = Checkpoint::new(step, t);
    ck.set_meta(&Meta { scheme: scheme_name(s.scheme).to_string(), dt: s.dt })?;
    ck.write(checkpoints_dir, tag, PART)?;
    Ok(())
}

/// The newest common checkpoint of run folder `dir`, checked against the case's settings `s`:
/// an error names the folder or file and what was expected. Newer folders passed over (a run
/// stopped while writing one) are named on stderr.
pub fn common_checkpoint(dir: &Path, s: &SchemeSettings) -> Result<Found, String> {
    let checkpoints = dir.join("checkpoints");
    let mut tags: Vec<String> = match std::fs::read_dir(&checkpoints) {
        Ok(entries) => entries
            .filter_map(Result::ok)
            .filter(|e| e.path().is_dir())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(format!("{}: {e}", checkpoints.display())),
    };
    // The tags of `checkpoint::tag_for_step` sort by step: newest first.
    tags.sort_unstable_by(|a, b| b.cmp(a));
    let mut search = Search::default();
    for tag in tags {
        match complete(&checkpoints.join(&tag)) {
            Ok((step, time)) => {
                search.found = Some(Found { dir: checkpoints.join(&tag), tag, step, time });
                break;
            }
            Err(reason) => search.skipped.push(Skipped { tag, reason }),
        }
    }
    for line in search.notices() {
        eprintln!("fsi: warning: {line}");
    }
    let Some(found) = search.found else {
        return Err(format!(
            "--restart {}: no common checkpoint in {}: no folder there holds {} complete (the \
             structure's and the launcher's at one step); checkpoints come every \
             output.checkpoint_every coupling steps",
            dir.display(),
            checkpoints.display(),
            PARTS.map(|p| format!("{p}.{}", checkpoint::EXTENSION)).join(", ")
        ));
    };
    let ck = Checkpoint::read(&checkpoints, &found.tag, PART).map_err(|e| e.to_string())?;
    let meta: Meta = ck.meta().map_err(|e| e.to_string())?;
    let file = found.dir.join(format!("{PART}.{}", checkpoint::EXTENSION));
    let want = scheme_name(s.scheme);
    if meta.scheme != want || meta.dt.to_bits() != s.dt.to_bits() {
        return Err(format!(
            "--restart: {} was written by a run with the {} scheme and coupling.dt = {:e}; the \
             case asks for {want} and coupling.dt = {:e}: restart with the case and --set \
             overrides of that run (only coupling.t_end may change)",
            file.display(),
            meta.scheme,
            meta.dt,
            s.dt
        ));
    }
    let t = found.step as f64 * s.dt;
    if found.time.to_bits() != t.to_bits() {
        return Err(format!(
            "--restart: {} is at step {} and t = {:e}, but step {} of coupling.dt = {:e} is at \
             t = {t:e}",
            file.display(),
            found.step,
            found.time,
            found.step,
            s.dt
        ));
    }
    Ok(found)
}

/// The step and time of the checkpoint folder `dir` if it is common: the launcher's and the
/// structure's parts intact and at one step (both count coupling steps), the fluid's intact (it
/// counts its own CFL steps); else why not.
fn complete(dir: &Path) -> Result<(u64, f64), String> {
    let read = |part: &str| {
        Checkpoint::read_file(&dir.join(format!("{part}.{}", checkpoint::EXTENSION)))
            .map_err(|e| e.to_string())
    };
    let launcher = read(PART)?;
    let structure = read("structure")?;
    read("fluid")?;
    if structure.step != launcher.step {
        return Err(format!(
            "part `structure` is at step {}, `{PART}` at {}",
            structure.step, launcher.step
        ));
    }
    Ok((launcher.step, launcher.time))
}

/// A restart needs both participants to announce [`capability::RESTART`]; the error names the
/// ones that do not.
pub fn check_capable(fluid: &Hello, structure: &Hello, labels: [String; 2]) -> Result<(), String> {
    let missing: Vec<&str> = [fluid, structure]
        .iter()
        .zip(&labels)
        .filter(|(h, _)| h.capabilities & capability::RESTART == 0)
        .map(|(_, l)| l.as_str())
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    Err(format!(
        "--restart: {} cannot continue a run from a checkpoint (its Hello does not announce the \
         restart capability); run the case from its start instead",
        missing.join(" and ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use interface_protocol::case::Scheme;

    fn settings(scheme: Scheme, dt: f64) -> SchemeSettings {
        SchemeSettings { scheme, dt, t_end: 1.0, n_steps: 8, checkpoint_every: 2 }
    }

    #[test]
    fn the_newest_common_checkpoint_of_the_case_is_found_and_others_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let ck = dir.path().join("checkpoints");
        let s = settings(Scheme::C0, 0.125);
        let e = common_checkpoint(dir.path(), &s).unwrap_err();
        assert!(e.contains("no common checkpoint") && e.contains("launcher.ckpt"), "{e}");
        for step in [2, 4] {
            let tag = checkpoint::tag_for_step(step);
            let t = step as f64 * 0.125;
            for part in ["structure", "fluid"] {
                Checkpoint::new(step, t).write(&ck, &tag, part).unwrap();
            }
            write_part(&ck, &tag, (step, t), &s).unwrap();
        }
        // Step 6: the fluid wrote its part, the structure did not.
        Checkpoint::new(6, 0.75).write(&ck, &checkpoint::tag_for_step(6), "fluid").unwrap();
        let found = common_checkpoint(dir.path(), &s).unwrap();
        assert_eq!((found.step, found.time), (4, 0.5));
        let e = common_checkpoint(dir.path(), &settings(Scheme::A6, 0.125)).unwrap_err();
        assert!(e.contains("step_0000000004/launcher.ckpt") && e.contains("C0 scheme"), "{e}");
        assert!(e.contains("asks for A6"), "{e}");
        let e = common_checkpoint(dir.path(), &settings(Scheme::C0, 0.1)).unwrap_err();
        assert!(e.contains("coupling.dt = 1.25e-1") && e.contains("coupling.dt = 1e-1"), "{e}");
    }

    #[test]
    fn a_participant_without_the_restart_capability_is_named() {
        let able = Hello { capabilities: capability::RESTART, ..Hello::default() };
        let unable = Hello::default();
        let labels = || ["fluid-solver (fluid)".to_string(), "peer.py (structure)".to_string()];
        assert!(check_capable(&able, &able, labels()).is_ok());
        let e = check_capable(&able, &unable, labels()).unwrap_err();
        assert!(e.contains("peer.py (structure) cannot") && !e.contains("fluid-solver"), "{e}");
    }
}
