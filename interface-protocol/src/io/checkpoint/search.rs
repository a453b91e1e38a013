//! Finding the checkpoint to restart from: the newest tag folder whose parts are all present,
//! intact and at one step, and the newer folders passed over, each with the reason.

use super::{check_tag, le8, part_path, Checkpoint, CheckpointError, EXTENSION, MAGIC};
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// The newest complete checkpoint found by [`latest`].
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    pub tag: String,
    pub dir: PathBuf,
    pub step: u64,
    pub time: f64,
}

/// A checkpoint folder newer than the one restarted from, passed over because it cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub struct Skipped {
    pub tag: String,
    /// Why: the part that is missing, damaged or at another step.
    pub reason: String,
}

/// What [`search`] found: the newest usable checkpoint and the newer ones it passed over.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Search {
    pub found: Option<Found>,
    /// Newest first.
    pub skipped: Vec<Skipped>,
}

impl Search {
    /// One line per skipped folder, for stderr: `checkpoint step_X is unreadable (why):
    /// restarting from step_Y` (or `...: no older checkpoint to restart from`).
    pub fn notices(&self) -> Vec<String> {
        let then = match &self.found {
            Some(f) => format!("restarting from {}", f.tag),
            None => "no older checkpoint to restart from".to_string(),
        };
        self.skipped
            .iter()
            .map(|s| format!("checkpoint {} is unreadable ({}): {then}", s.tag, s.reason))
            .collect()
    }
}

/// The tag folder under `checkpoints_dir` with the highest step whose `parts` are all present,
/// intact and at the same step; `None` if there is none. Incomplete or damaged folders newer than
/// the one returned (a run killed while writing leaves one) are skipped, each with a line on
/// stderr naming it, why, and the checkpoint used instead ([`Search::notices`]); use [`search`]
/// to get them instead.
pub fn latest(checkpoints_dir: &Path, parts: &[&str]) -> Result<Option<Found>, CheckpointError> {
    let found = search(checkpoints_dir, parts)?;
    for line in found.notices() {
        eprintln!("warning: {line}");
    }
    Ok(found.found)
}

/// [`latest`] without the stderr lines: the newest complete checkpoint and every newer folder
/// passed over, with the reason. Candidates are ordered by the step in their file headers, so
/// only the newest folders are read in full.
pub fn search(checkpoints_dir: &Path, parts: &[&str]) -> Result<Search, CheckpointError> {
    let io_err =
        |source| CheckpointError::Io { path: checkpoints_dir.display().to_string(), source };
    let entries = match fs::read_dir(checkpoints_dir) {
        Ok(e) => e,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Search::default()),
        Err(e) => return Err(io_err(e)),
    };
    let Some(first) = parts.first() else { return Ok(Search::default()) };
    // (step from the first part's header, tag, folder)
    let mut candidates: Vec<(u64, String, PathBuf)> = Vec::new();
    // Folders whose first part has no readable header: their step is unknown.
    let mut unreadable: Vec<Skipped> = Vec::new();
    for entry in entries {
        let entry = entry.map_err(io_err)?;
        let tag = entry.file_name().to_string_lossy().into_owned();
        if check_tag(&tag).is_err() || !entry.path().is_dir() {
            continue;
        }
        match read_step(&part_path(&entry.path(), first)) {
            Some(step) => candidates.push((step, tag, entry.path())),
            None => {
                let reason = match Checkpoint::read_file(&part_path(&entry.path(), first)) {
                    Err(e) => why(first, &e),
                    Ok(_) => format!("part `{first}` has no readable header"),
                };
                unreadable.push(Skipped { tag, reason });
            }
        }
    }
    candidates.sort();
    let mut skipped = Vec::new();
    let mut found = None;
    'tags: for (_, tag, dir) in candidates.into_iter().rev() {
        let mut at: Option<(u64, f64)> = None;
        for part in parts {
            match Checkpoint::read_file(&part_path(&dir, part)) {
                Ok(c) if at.is_none_or(|(s, _)| s == c.step) => at = Some((c.step, c.time)),
                Ok(c) => {
                    let (s, _) = at.expect("checked above");
                    let reason = format!("part `{part}` is at step {}, `{first}` at {s}", c.step);
                    skipped.push(Skipped { tag, reason });
                    continue 'tags;
                }
                Err(e) => {
                    skipped.push(Skipped { tag, reason: why(part, &e) });
                    continue 'tags;
                }
            }
        }
        let (step, time) = at.expect("parts is not empty");
        found = Some(Found { tag, dir, step, time });
        break;
    }
    // A folder of unknown step matters when its name sorts after the one used (the tags of
    // [`tag_for_step`] sort by step).
    unreadable.retain(|s| found.as_ref().is_none_or(|f: &Found| s.tag > f.tag));
    skipped.extend(unreadable);
    skipped.sort_by(|a, b| b.tag.cmp(&a.tag));
    Ok(Search { found, skipped })
}

/// The checkpoint `--restart dir` names for `part`: `dir` itself when it is one checkpoint
/// folder (it holds `<part>.ckpt`: what `fsi run --restart` passes each participant, the newest
/// checkpoint every part of the run wrote), else the newest complete one under
/// `dir/checkpoints` ([`latest`]); `None` if there is none. A named folder whose part is
/// damaged is an error, not passed over.
pub fn restart_point(dir: &Path, part: &str) -> Result<Option<Found>, CheckpointError> {
    check_tag(part)?;
    let file = part_path(dir, part);
    if !file.is_file() {
        return latest(&dir.join("checkpoints"), &[part]);
    }
    let ck = Checkpoint::read_file(&file)?;
    let tag = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(Some(Found { tag, dir: dir.to_path_buf(), step: ck.step, time: ck.time }))
}

/// Why `part` cannot be used, without the path (the notice names the folder).
fn why(part: &str, e: &CheckpointError) -> String {
    let file = format!("{part}.{EXTENSION}");
    match e {
        CheckpointError::Io { source, .. } if source.kind() == io::ErrorKind::NotFound => {
            format!("{file} is missing")
        }
        CheckpointError::Io { source, .. } => format!("{file}: {source}"),
        CheckpointError::Truncated { what, needed, len, .. } => {
            format!("{file} is truncated: {what} needs bytes up to {needed}, the file has {len}")
        }
        CheckpointError::Corrupt { reason, .. } => format!("{file}: {reason}"),
        other => format!("{file}: {other}"),
    }
}

/// The step in a checkpoint file's header, without reading the rest.
fn read_step(path: &Path) -> Option<u64> {
    use std::io::Read;
    let mut head = [0u8; 24];
    fs::File::open(path).and_then(|mut f| f.read_exact(&mut head)).ok()?;
    (head[..8] == *MAGIC).then(|| le8(&head[16..24]))
}

#[cfg(test)]
mod tests {
    use super::super::tag_for_step;
    use super::super::tests::{overwrite, sample};
    use super::*;

    #[test]
    fn a_restart_names_a_run_folder_or_one_checkpoint_folder() {
        let dir = tempfile::tempdir().unwrap();
        let ck = dir.path().join("checkpoints");
        assert_eq!(restart_point(dir.path(), "fluid").unwrap(), None);
        for step in [10, 20] {
            sample(step).write(&ck, &tag_for_step(step), "fluid").unwrap();
        }
        assert_eq!(restart_point(dir.path(), "fluid").unwrap().unwrap().step, 20);
        let one = restart_point(&ck.join(tag_for_step(10)), "fluid").unwrap().unwrap();
        assert_eq!((one.tag.as_str(), one.step), ("step_0000000010", 10));
        assert_eq!(one.dir, ck.join(tag_for_step(10)));
        // A named folder without the part is a run folder without checkpoints.
        assert_eq!(restart_point(&ck.join(tag_for_step(10)), "structure").unwrap(), None);
    }

    #[test]
    fn latest_skips_incomplete_and_damaged_folders() {
        let dir = tempfile::tempdir().unwrap();
        let ck = dir.path();
        assert_eq!(latest(ck, &["fluid", "structure"]).unwrap(), None);
        for step in [10, 20, 30, 40] {
            sample(step).write(ck, &tag_for_step(step), "fluid").unwrap();
        }
        for step in [10, 20, 30] {
            sample(step).write(ck, &tag_for_step(step), "structure").unwrap();
        }
        // 40 lacks its structure part; 30's structure part is truncated.
        let p30 = ck.join(tag_for_step(30)).join("structure.ckpt");
        let b = fs::read(&p30).unwrap();
        overwrite(&p30, &b[..b.len() - 9]);
        // A leftover temporary of an interrupted write is ignored.
        fs::write(ck.join(tag_for_step(20)).join("fluid.ckpt.tmp.999"), b"partial").unwrap();
        let found = latest(ck, &["fluid", "structure"]).unwrap().unwrap();
        assert_eq!((found.tag.as_str(), found.step), ("step_0000000020", 20));
        assert_eq!(found.dir, ck.join("step_0000000020"));
        assert_eq!(found.time, 20.0 * 1e-3);
        assert_eq!(latest(ck, &["fluid"]).unwrap().unwrap().step, 40);
    }

    #[test]
    fn a_damaged_newest_checkpoint_is_named_with_the_one_used_instead() {
        let dir = tempfile::tempdir().unwrap();
        let ck = dir.path();
        for step in [10, 20, 30, 40] {
            sample(step).write(ck, &tag_for_step(step), "fluid").unwrap();
            sample(step).write(ck, &tag_for_step(step), "structure").unwrap();
        }
        // 40: a flipped bit in the structure part; 30: no structure part; 20: parts at two steps.
        let p40 = ck.join(tag_for_step(40)).join("structure.ckpt");
        let mut b = fs::read(&p40).unwrap();
        let at = b.len() / 2;
        b[at] ^= 0x01;
        overwrite(&p40, &b);
        fs::remove_file(ck.join(tag_for_step(30)).join("structure.ckpt")).unwrap();
        sample(21).write(ck, &tag_for_step(20), "structure").unwrap();
        // A folder whose first part is not even a checkpoint, named after the one used.
        fs::create_dir(ck.join("step_0000000050")).unwrap();
        fs::write(ck.join("step_0000000050/fluid.ckpt"), b"junk").unwrap();
        // And one named before it, which does not matter.
        fs::create_dir(ck.join("step_0000000005")).unwrap();

        let found = search(ck, &["fluid", "structure"]).unwrap();
        assert_eq!(found.found.as_ref().map(|f| f.step), Some(10));
        let tags: Vec<&str> = found.skipped.iter().map(|s| s.tag.as_str()).collect();
        assert_eq!(
            tags,
            ["step_0000000050", "step_0000000040", "step_0000000030", "step_0000000020"]
        );
        let notices = found.notices();
        assert_eq!(notices.len(), 4);
        for n in &notices {
            assert!(n.ends_with(": restarting from step_0000000010"), "{n}");
        }
        let n40 = &notices[1];
        assert!(
            n40.starts_with(
                "checkpoint step_0000000040 is unreadable (structure.ckpt: checksum mismatch"
            ),
            "{n40}"
        );
        assert!(notices[0].contains("fluid.ckpt is truncated"), "{}", notices[0]);
        assert!(notices[2].contains("structure.ckpt is missing"), "{}", notices[2]);
        assert!(
            notices[3].contains("part `structure` is at step 21, `fluid` at 20"),
            "{}",
            notices[3]
        );
        // `latest` returns the same folder (and prints the notices).
        assert_eq!(latest(ck, &["fluid", "structure"]).unwrap(), found.found);

        // Nothing usable: the notices say so.
        fs::remove_dir_all(ck.join(tag_for_step(10))).unwrap();
        let none = search(ck, &["fluid", "structure"]).unwrap();
        assert_eq!(none.found, None);
        assert!(none.notices()[0].ends_with(": no older checkpoint to restart from"));
        // An intact set reports nothing.
        let clean = tempfile::tempdir().unwrap();
        sample(1).write(clean.path(), &tag_for_step(1), "fluid").unwrap();
        assert!(search(clean.path(), &["fluid"]).unwrap().skipped.is_empty());
    }
}
