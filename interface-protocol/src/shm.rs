//! Shared-memory housekeeping (DESIGN §3): room in `/dev/shm` before allocating (a full tmpfs
//! shows up later as SIGBUS), the launcher's claim on its run id ([`RunLock`]), removal of every
//! file of a run, and of runs that died.

use crate::endpoint::ProtocolError;
use crate::services;
use iceoryx2::prelude::{ipc, CallbackProgression, Node, NodeState};
use std::path::{Path, PathBuf};

mod lock;
pub use lock::{lock_path, RunLock};

/// Where iceoryx2 maps its shared memory.
pub const SHM_DIR: &str = "/dev/shm";
/// Where iceoryx2 keeps its node and service descriptions (`Config::global.root_path`).
pub const ROOT_DIR: &str = "/tmp/iceoryx2";

/// Free bytes of the file system holding `dir`.
pub fn free_bytes(dir: &Path) -> Result<u64, ProtocolError> {
    let c = std::ffi::CString::new(dir.as_os_str().as_encoded_bytes())
        .map_err(|_| ProtocolError::Setup(format!("bad path {}", dir.display())))?;
    // SAFETY: `statvfs` writes into the zeroed struct we own; `c` is a valid C string.
    let (rc, st) = unsafe {
        let mut st: libc::statvfs = std::mem::zeroed();
        (libc::statvfs(c.as_ptr(), &mut st), st)
    };
    if rc != 0 {
        return Err(ProtocolError::Setup(format!(
            "cannot query free space of {}: {}",
            dir.display(),
            std::io::Error::last_os_error()
        )));
    }
    // The field types differ between platforms (u32 on some 32-bit targets).
    #[allow(clippy::unnecessary_cast)]
    Ok(st.f_bavail as u64 * st.f_frsize as u64)
}

/// Fails with a clear message unless `/dev/shm` has room for `bytes` (`what` names the buffer).
pub fn ensure_capacity(bytes: u64, what: &str) -> Result<(), ProtocolError> {
    let free = free_bytes(Path::new(SHM_DIR))?;
    if bytes > free {
        return Err(ProtocolError::Setup(format!(
            "{SHM_DIR} has {} MiB free but {what} needs {} MiB: free space there or enlarge the \
             tmpfs (mount -o remount,size=...)",
            free >> 20,
            bytes.div_ceil(1 << 20)
        )));
    }
    Ok(())
}

/// Every file of a run: in `/dev/shm` and (recursively) under `/tmp/iceoryx2`.
pub fn run_files(run_id: &str) -> Vec<PathBuf> {
    let prefix = services::prefix(run_id);
    let mut out = Vec::new();
    collect(Path::new(SHM_DIR), &prefix, false, &mut out);
    collect(Path::new(ROOT_DIR), &prefix, true, &mut out);
    out
}

fn collect(dir: &Path, prefix: &str, recursive: bool, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let path = e.path();
        let is_dir = e.file_type().is_ok_and(|t| t.is_dir());
        if e.file_name().to_string_lossy().starts_with(prefix) {
            out.push(path);
        } else if recursive && is_dir {
            collect(&path, prefix, true, out);
        }
    }
}

/// Removes every file of a run (call it only when no process of the run is alive). Returns the
/// number of files removed.
pub fn cleanup_run(run_id: &str) -> Result<usize, ProtocolError> {
    cleanup_run_except(run_id, None)
}

/// `cleanup_run`, keeping the file `keep` (the lock of the launcher that reuses the run id).
fn cleanup_run_except(run_id: &str, keep: Option<&Path>) -> Result<usize, ProtocolError> {
    services::validate_run_id(run_id)?;
    let mut removed = 0;
    for path in run_files(run_id).into_iter().filter(|p| Some(p.as_path()) != keep) {
        let r = if path.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
        match r {
            Ok(()) => {
                removed += 1;
                remove_empty_node_dir(&path);
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => {
                return Err(ProtocolError::Setup(format!("cannot remove {}: {e}", path.display())))
            }
        }
    }
    Ok(removed)
}

/// iceoryx2 keeps a node's files in `/tmp/iceoryx2/nodes/<node id>/`, a folder without the run's
/// prefix: it goes with the node's last file.
fn remove_empty_node_dir(removed: &Path) {
    let Some(dir) = removed.parent() else { return };
    if dir.parent() == Some(Path::new(ROOT_DIR).join("nodes").as_path()) {
        // Fails, harmlessly, while the folder holds anything.
        let _ = std::fs::remove_dir(dir);
    }
}

/// Run ids that own files in `/dev/shm` or `/tmp/iceoryx2`.
pub fn runs_on_disk() -> Vec<String> {
    let mut ids = std::collections::BTreeSet::new();
    for dir in [Path::new(SHM_DIR), Path::new(ROOT_DIR)] {
        let mut files = Vec::new();
        collect(dir, "fsi_", true, &mut files);
        for f in files {
            let name = f.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            if let Some(id) = name.strip_prefix("fsi_").and_then(|r| r.split('_').next()) {
                if services::validate_run_id(id).is_ok() {
                    ids.insert(id.to_string());
                }
            }
        }
    }
    ids.into_iter().collect()
}

/// Whether any node of the run is alive (or cannot be inspected, which counts as alive). A run
/// with no file under `/tmp/iceoryx2` (where node descriptions live) has no node.
pub fn run_has_live_node(run_id: &str) -> bool {
    let Ok(config) = services::config(run_id) else { return false };
    let mut node_files = Vec::new();
    collect(Path::new(ROOT_DIR), &services::prefix(run_id), true, &mut node_files);
    if node_files.is_empty() {
        return false;
    }
    let mut alive = false;
    let listed = Node::<ipc::Service>::list(&config, |state| {
        if !matches!(state, NodeState::Dead(_)) {
            alive = true;
            return CallbackProgression::Stop;
        }
        CallbackProgression::Continue
    });
    alive || listed.is_err()
}

/// A run whose files changed this recently may be starting up (its nodes not yet listed): it is
/// never treated as stale.
pub const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(30);

/// Whether any file of the run was modified within `min_age` (or its age cannot be read).
fn run_is_recent(run_id: &str, min_age: std::time::Duration) -> bool {
    run_files(run_id).iter().any(|f| {
        std::fs::symlink_metadata(f)
            .and_then(|m| m.modified())
            .map_or(true, |t| t.elapsed().map_or(true, |age| age < min_age))
    })
}

/// Removes the files of every dead run (DESIGN §3: stale resources of dead runs are cleaned at
/// start). A run started by a launcher is dead once its launcher's [`RunLock`] is free and none of
/// its nodes is alive; a run without a lock (participants joined by hand, `fsi bench`) once its
/// nodes are all dead and its files older than `min_age` (launchers pass `STALE_AFTER`, so a run
/// that is starting up is safe). Returns the run ids cleaned.
pub fn cleanup_stale_runs(min_age: std::time::Duration) -> Vec<String> {
    runs_on_disk().into_iter().filter(|id| cleanup_if_stale(id, min_age)).collect()
}

/// Removes a run's files if it is dead (see [`cleanup_stale_runs`]); returns whether it did.
pub fn cleanup_if_stale(run_id: &str, min_age: std::time::Duration) -> bool {
    match lock::claim_dead(run_id) {
        lock::Claim::Held => false,
        // Held while the files go, so that no launcher reuses the id half-way.
        lock::Claim::Dead(_claim) => !run_has_live_node(run_id) && cleanup_run(run_id).is_ok(),
        lock::Claim::Absent => {
            !run_is_recent(run_id, min_age)
                && !run_has_live_node(run_id)
                && cleanup_run(run_id).is_ok()
        }
    }
}
