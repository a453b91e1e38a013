//! The launcher's claim on a run id: `/dev/shm/fsi_<run_id>_launcher.lock`, holding the
//! launcher's pid under an open-file-description write lock (`F_OFD_SETLK`) for as long as the
//! launcher lives. The kernel drops the lock when the process ends, however it ends, so a free
//! lock is a dead run and a held one a live run, without guessing from file ages.
//!
//! The file appears already locked and holding its pid: it is written under a private name and
//! hard-linked into place. A second launcher given the same id fails at once naming the pid; one
//! that finds a free lock (its launcher was killed) takes it over and removes the dead run's
//! other files before it starts.

use super::{cleanup_run_except, SHM_DIR};
use crate::endpoint::ProtocolError;
use crate::services;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::os::fd::AsRawFd;
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// How long `acquire` retries while a lock is held by a process that is gone (a stale-run
/// clean-up holding it for a moment) before it reports the run id as in use.
const TAKEOVER_WAIT: Duration = Duration::from_secs(1);

/// The lock file of a run.
pub fn lock_path(run_id: &str) -> PathBuf {
    Path::new(SHM_DIR).join(format!("{}launcher.lock", services::prefix(run_id)))
}

/// A launcher's claim on its run id; released when dropped (or when the process dies).
#[derive(Debug)]
pub struct RunLock {
    _file: File,
    path: PathBuf,
}

/// What a look at a run's lock found.
pub(super) enum Claim {
    /// No lock file: the run was not started by a launcher (or is gone).
    Absent,
    /// A live launcher holds it.
    Held,
    /// Its launcher died; this claim holds the lock until dropped.
    Dead(#[allow(dead_code)] File),
}

impl RunLock {
    /// Claims `run_id` for this process. Fails with "run id X is in use by pid P" while another
    /// launcher holds it; takes over the lock of a dead launcher and removes that run's files.
    pub fn acquire(run_id: &str) -> Result<RunLock, ProtocolError> {
        services::validate_run_id(run_id)?;
        let path = lock_path(run_id);
        let give_up = Instant::now() + TAKEOVER_WAIT;
        loop {
            if let Some(file) = create_locked(&path)? {
                return Ok(RunLock { _file: file, path });
            }
            match open_existing(&path)? {
                Opened::Gone => {}
                Opened::Ours(mut file) => {
                    write_pid(&mut file)?;
                    cleanup_run_except(run_id, Some(&path))?;
                    return Ok(RunLock { _file: file, path });
                }
                Opened::Held(pid) => {
                    // A holder that is gone is a clean-up of the dead run at work: wait for it.
                    if pid.is_some_and(process_alive) || Instant::now() >= give_up {
                        let by =
                            pid.map_or_else(|| "another launcher".into(), |p| format!("pid {p}"));
                        return Err(ProtocolError::Setup(format!(
                            "run id {run_id} is in use by {by} (its lock is {}): choose another \
                             --run-id, or leave it out for a fresh one",
                            path.display()
                        )));
                    }
                }
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Looks at a run's lock for a clean-up: a free lock is taken and returned in `Claim::Dead`.
pub(super) fn claim_dead(run_id: &str) -> Claim {
    match open_existing(&lock_path(run_id)) {
        Ok(Opened::Gone) => Claim::Absent,
        Ok(Opened::Ours(file)) => Claim::Dead(file),
        // Unreadable counts as held: never remove what might be alive.
        Ok(Opened::Held(_)) | Err(_) => Claim::Held,
    }
}

/// Creates the lock file, locked and holding this pid; `None` if it exists already.
fn create_locked(path: &Path) -> Result<Option<File>, ProtocolError> {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let private = Path::new(SHM_DIR).join(format!(
        ".fsi-claim-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::SeqCst)
    ));
    let setup = |doing: &str, e: std::io::Error| {
        ProtocolError::Setup(format!("cannot {doing} {}: {e}", path.display()))
    };
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create_new(true)
        .mode(0o644)
        .open(&private)
        .map_err(|e| setup("create the lock file next to", e))?;
    let linked = lock(&file)
        .and_then(|locked| {
            debug_assert!(locked, "a new private file is locked by nobody");
            file.write_all(std::process::id().to_string().as_bytes())
        })
        .and_then(|()| std::fs::hard_link(&private, path));
    let _ = std::fs::remove_file(&private);
    match linked {
        Ok(()) => Ok(Some(file)),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(None),
        Err(e) => Err(setup("create the lock file", e)),
    }
}

/// What opening an existing lock file found.
enum Opened {
    /// No such file (any more).
    Gone,
    /// Locked by this call: its launcher is dead.
    Ours(File),
    /// Locked by someone else, with the pid the file holds.
    Held(Option<u32>),
}

fn open_existing(path: &Path) -> Result<Opened, ProtocolError> {
    let setup =
        |e: std::io::Error| ProtocolError::Setup(format!("cannot open {}: {e}", path.display()));
    let mut file = match OpenOptions::new().read(true).write(true).open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Opened::Gone),
        Err(e) => return Err(setup(e)),
    };
    if !lock(&file).map_err(setup)? {
        let mut text = String::new();
        let _ = file.read_to_string(&mut text);
        return Ok(Opened::Held(text.trim().parse().ok()));
    }
    // Removed (and perhaps created anew) between the open and the lock: look again.
    let same = match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    };
    Ok(if same { Opened::Ours(file) } else { Opened::Gone })
}

fn write_pid(file: &mut File) -> Result<(), ProtocolError> {
    file.set_len(0)
        .and_then(|()| file.rewind())
        .and_then(|()| file.write_all(std::process::id().to_string().as_bytes()))
        .map_err(|e| ProtocolError::Setup(format!("cannot write the run's lock file: {e}")))
}

/// Takes a write lock on the whole file without waiting: `Ok(false)` if another open file
/// description holds one (in this process or another).
fn lock(file: &File) -> std::io::Result<bool> {
    // SAFETY: `flock` is plain data; zeroed is a valid value, and `l_pid` must be 0 for OFD locks.
    let mut fl: libc::flock = unsafe { std::mem::zeroed() };
    fl.l_type = libc::F_WRLCK as libc::c_short;
    fl.l_whence = libc::SEEK_SET as libc::c_short;
    // SAFETY: `fcntl(F_OFD_SETLK)` reads the `flock` we own; the descriptor is open for as long
    // as `file` lives.
    let rc = unsafe { libc::fcntl(file.as_raw_fd(), libc::F_OFD_SETLK, &fl) };
    if rc == 0 {
        return Ok(true);
    }
    let e = std::io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EAGAIN) | Some(libc::EACCES) => Ok(false),
        _ => Err(e),
    }
}

fn process_alive(pid: u32) -> bool {
    // SAFETY: `kill(pid, 0)` only checks whether the process exists.
    let found = unsafe { libc::kill(pid as libc::pid_t, 0) } == 0;
    found || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn id(tag: &str) -> String {
        format!("t{}-lock-{tag}", std::process::id())
    }

    #[test]
    fn a_second_claim_names_the_holder_and_a_released_one_is_taken() {
        let run_id = id("twice");
        let first = RunLock::acquire(&run_id).unwrap();
        assert_eq!(std::fs::read_to_string(first.path()).unwrap(), std::process::id().to_string());
        let e = RunLock::acquire(&run_id).unwrap_err().to_string();
        let want = format!("run id {run_id} is in use by pid {}", std::process::id());
        assert!(e.contains(&want), "{e}");
        assert!(matches!(claim_dead(&run_id), Claim::Held));
        drop(first);
        let again = RunLock::acquire(&run_id).unwrap();
        assert!(again.path().is_file());
        super::super::cleanup_run(&run_id).unwrap();
        assert!(super::super::run_files(&run_id).is_empty());
    }

    #[test]
    fn taking_over_a_dead_launchers_lock_removes_its_runs_files() {
        let run_id = id("takeover");
        let dead = RunLock::acquire(&run_id).unwrap();
        let leftover =
            Path::new(SHM_DIR).join(format!("{}x.global_mgmt", services::prefix(&run_id)));
        std::fs::write(&leftover, b"x").unwrap();
        drop(dead);
        let lock = RunLock::acquire(&run_id).unwrap();
        assert!(!leftover.exists(), "the dead run's file was kept");
        assert_eq!(super::super::run_files(&run_id), vec![lock.path().to_path_buf()]);
        drop(lock);
        // A free lock is a dead run: cleaned at once, whatever the age of its files.
        std::fs::write(&leftover, b"x").unwrap();
        assert!(super::super::cleanup_if_stale(&run_id, Duration::from_secs(3600)));
        assert!(super::super::run_files(&run_id).is_empty());
    }
}
