//! The malformed-input corpus: every entry of `tests/corpus/manifest.txt` run once against the
//! release binaries, each in a fresh temporary copy of its folder, under a deadline and a memory
//! limit. Each run is classified:
//!
//! - `clear`: refused (non-zero exit) with every citation of the entry on stderr: the file and
//!   line, the field, the element;
//! - `vague`: refused, but a citation is missing;
//! - `silent`: accepted (exit 0) although the input is malformed;
//! - `abort`: killed by a signal, exit 101 or "panicked" on stderr;
//! - `hang`: still running at the deadline (then killed with its process group);
//! - `valid` / `refused`: a valid base accepted / refused.
//!
//! The test prints the counts by outcome and every entry that is not `clear` or `valid` with its
//! stderr, then asserts there are none. Build the binaries first:
//! `cargo build --release --bins && cargo test --release -p fsi-system-tests --test corpus --
//! --nocapture`.
//!
//! Environment: `FSI_CORPUS_ONLY=<text>` runs the entries whose name contains it,
//! `FSI_CORPUS_SHOW=all` prints the messages of the clear entries too, `FSI_CORPUS_JOBS`
//! (default 2) runs that many at once, `FSI_CORPUS_DEADLINE_S` (default 20) and
//! `FSI_CORPUS_MEMORY_GB` (default 4, the address-space limit of each run) bound them.

use fsi_system_tests::{bin, bin_dir};
use std::collections::BTreeMap;
use std::fmt;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// What an entry should produce.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Expect {
    Error,
    Warning,
    Ok,
}

/// One line of the manifest.
#[derive(Debug, Clone)]
struct Entry {
    name: String,
    expect: Expect,
    program: String,
    args: Vec<String>,
    /// Each must be on stderr; `a | b` is satisfied by either.
    cites: Vec<String>,
    /// Line in the manifest.
    line: usize,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Outcome {
    Clear,
    Valid,
    Vague,
    Silent,
    Abort,
    Hang,
    Refused,
}

impl Outcome {
    const ALL: [Outcome; 7] = [
        Outcome::Clear,
        Outcome::Valid,
        Outcome::Vague,
        Outcome::Silent,
        Outcome::Abort,
        Outcome::Hang,
        Outcome::Refused,
    ];

    fn is_good(self) -> bool {
        matches!(self, Outcome::Clear | Outcome::Valid)
    }
}

impl fmt::Display for Outcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Outcome::Clear => "clear",
            Outcome::Valid => "valid",
            Outcome::Vague => "vague",
            Outcome::Silent => "silent",
            Outcome::Abort => "abort",
            Outcome::Hang => "hang",
            Outcome::Refused => "refused",
        })
    }
}

/// How one entry ran.
struct Run {
    entry: Entry,
    outcome: Outcome,
    /// Exit code, or the signal that ended it.
    status: String,
    stderr: String,
    missing: Vec<String>,
    elapsed: Duration,
}

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus")
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// The entries of `manifest.txt`; panics naming the line of a malformed one.
fn manifest() -> Vec<Entry> {
    let path = corpus_dir().join("manifest.txt");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut entries = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = line.split(';').map(str::trim).collect();
        let [name, expect, command, cites] = cols[..] else {
            panic!("{}:{}: expected `entry ; expect ; command ; citations`", path.display(), k + 1)
        };
        let expect = match expect {
            "error" => Expect::Error,
            "warning" => Expect::Warning,
            "ok" => Expect::Ok,
            other => panic!(
                "{}:{}: expect `{other}`: expected error, warning or ok",
                path.display(),
                k + 1
            ),
        };
        let mut words = command.split_whitespace().map(str::to_string);
        let program = words.next().unwrap_or_default();
        let cites: Vec<String> = match cites {
            "-" => Vec::new(),
            c => c.split(" & ").map(|s| s.trim().to_string()).collect(),
        };
        assert!(
            expect == Expect::Ok || !cites.is_empty(),
            "{}:{}: an error entry names what its message must cite",
            path.display(),
            k + 1
        );
        entries.push(Entry {
            name: name.to_string(),
            expect,
            program,
            args: words.collect(),
            cites,
            line: k + 1,
        });
    }
    entries
}

/// Copies `from` into `to`, recursively, keeping file modes (scripts stay executable).
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("create a scratch folder");
    for e in std::fs::read_dir(from).expect("read a corpus folder").flatten() {
        let target = to.join(e.file_name());
        if e.file_type().expect("file type").is_dir() {
            copy_tree(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), &target).expect("copy a corpus file");
        }
    }
}

/// Limits the address space of the process about to run `exec` (a runaway allocation then
/// fails instead of filling the machine's memory) and puts it in a process group of its own.
fn contain(cmd: &mut Command, bytes: u64) {
    cmd.process_group(0);
    // SAFETY: the closure runs in the forked child before exec and only calls `setrlimit`,
    // which is async-signal-safe; it allocates nothing and touches no lock.
    unsafe {
        cmd.pre_exec(move || {
            let limit = libc::rlimit { rlim_cur: bytes, rlim_max: bytes };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

/// Kills the process group `pgid` (the entry's process and the participants it started).
fn kill_group(pgid: u32) {
    // SAFETY: `kill` only sends a signal, to a process group this test created.
    unsafe {
        libc::kill(-(pgid as i32), libc::SIGKILL);
    }
}

fn run_entry(entry: &Entry, deadline: Duration, memory: u64) -> Run {
    let scratch = tempfile::Builder::new().prefix("fsi-corpus-").tempdir().expect("a temp dir");
    let dir = scratch.path().join(&entry.name);
    let source = corpus_dir().join(&entry.name);
    if source.is_dir() {
        copy_tree(&source, &dir);
    } else {
        std::fs::create_dir_all(&dir).expect("create the entry folder");
    }
    copy_tree(&corpus_dir().join("meshes"), &scratch.path().join("meshes"));
    let err_path = scratch.path().join("stderr");
    let path = std::env::join_paths(
        std::iter::once(bin_dir())
            .chain(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())),
    )
    .expect("a PATH");
    let mut cmd = Command::new(bin(&entry.program));
    cmd.args(&entry.args)
        .current_dir(&dir)
        .env("PATH", path)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err_path).expect("a stderr file"));
    contain(&mut cmd, memory);
    let started = Instant::now();
    let mut child = cmd.spawn().unwrap_or_else(|e| panic!("{}: cannot start: {e}", entry.name));
    let pgid = child.id();
    let status = loop {
        if let Some(s) = child.try_wait().expect("try_wait") {
            break Some(s);
        }
        if started.elapsed() >= deadline {
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let elapsed = started.elapsed();
    kill_group(pgid);
    if status.is_none() {
        let _ = child.wait();
    }
    let stderr =
        String::from_utf8_lossy(&std::fs::read(&err_path).unwrap_or_default()).into_owned();
    let missing: Vec<String> = entry
        .cites
        .iter()
        .filter(|c| !c.split(" | ").any(|alt| stderr.contains(alt.trim())))
        .cloned()
        .collect();
    let (outcome, status) = match status {
        None => (Outcome::Hang, format!("killed after {deadline:?}")),
        Some(s) => {
            let code = s.code();
            let shown = match (code, s.signal()) {
                (Some(c), _) => format!("exit {c}"),
                (None, Some(sig)) => format!("signal {sig}"),
                (None, None) => "?".to_string(),
            };
            let outcome = if code.is_none() || code == Some(101) || stderr.contains("panicked") {
                Outcome::Abort
            } else {
                let ok = code == Some(0);
                match entry.expect {
                    Expect::Ok if ok => Outcome::Valid,
                    Expect::Ok => Outcome::Refused,
                    _ if missing.is_empty() && (!ok || entry.expect == Expect::Warning) => {
                        Outcome::Clear
                    }
                    _ if ok => Outcome::Silent,
                    _ => Outcome::Vague,
                }
            };
            (outcome, shown)
        }
    };
    Run { entry: entry.clone(), outcome, status, stderr, missing, elapsed }
}

/// The first lines of a message, indented.
fn excerpt(text: &str, lines: usize) -> String {
    let mut out: Vec<String> = text.lines().take(lines).map(|l| format!("      {l}")).collect();
    let total = text.lines().count();
    if total > lines {
        out.push(format!("      ... ({} more lines)", total - lines));
    }
    if out.is_empty() {
        out.push("      (nothing on stderr)".to_string());
    }
    out.join("\n")
}

#[test]
fn the_manifest_lists_every_entry_folder_once() {
    let entries = manifest();
    let mut seen = BTreeMap::new();
    for e in &entries {
        if let Some(first) = seen.insert(e.name.clone(), e.line) {
            panic!("manifest.txt:{}: `{}` is listed at line {first} too", e.line, e.name);
        }
    }
    for d in std::fs::read_dir(corpus_dir()).expect("tests/corpus").flatten() {
        let name = d.file_name().to_string_lossy().into_owned();
        if d.path().is_dir() && name != "meshes" {
            assert!(seen.contains_key(&name), "tests/corpus/{name} is not in manifest.txt");
        }
    }
    let errors = entries.iter().filter(|e| e.expect != Expect::Ok).count();
    assert!(errors >= 90, "only {errors} malformed inputs in the corpus");
}

#[test]
fn every_malformed_input_gets_a_clear_error() {
    let only = std::env::var("FSI_CORPUS_ONLY").unwrap_or_default();
    let entries: Vec<Entry> = manifest().into_iter().filter(|e| e.name.contains(&only)).collect();
    let jobs = env_or("FSI_CORPUS_JOBS", 2usize).max(1);
    let deadline = Duration::from_secs_f64(env_or("FSI_CORPUS_DEADLINE_S", 20.0));
    let memory = (env_or("FSI_CORPUS_MEMORY_GB", 4.0f64) * (1u64 << 30) as f64) as u64;
    let started = Instant::now();
    let next = AtomicUsize::new(0);
    let runs = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                let Some(e) = entries.get(k) else { break };
                let r = run_entry(e, deadline, memory);
                runs.lock().unwrap().push(r);
            });
        }
    });
    let mut runs = runs.into_inner().unwrap();
    runs.sort_by_key(|r| (r.outcome, r.entry.line));
    let mut counts: BTreeMap<Outcome, usize> = BTreeMap::new();
    for r in &runs {
        *counts.entry(r.outcome).or_default() += 1;
    }
    let show_all = std::env::var("FSI_CORPUS_SHOW").is_ok_and(|v| v == "all");
    let mut report = String::new();
    for r in runs.iter().filter(|r| show_all || !r.outcome.is_good()) {
        report.push_str(&format!(
            "[{}] {} (manifest.txt:{}): {} {} -> {} in {:.2} s\n",
            r.outcome,
            r.entry.name,
            r.entry.line,
            r.entry.program,
            r.entry.args.join(" "),
            r.status,
            r.elapsed.as_secs_f64()
        ));
        if !r.missing.is_empty() {
            report.push_str(&format!("    missing: {}\n", r.missing.join(" & ")));
        }
        report.push_str(&excerpt(&r.stderr, 12));
        report.push('\n');
    }
    println!("\ncorpus: {} entries in {:.1} s", runs.len(), started.elapsed().as_secs_f64());
    println!("{:>8}  count", "outcome");
    for o in Outcome::ALL {
        println!("{:>8}  {}", o.to_string(), counts.get(&o).copied().unwrap_or(0));
    }
    if !report.is_empty() {
        println!(
            "\n{}:\n{report}",
            if show_all { "every entry" } else { "entries that are not clear" }
        );
    }
    let bad: usize = runs.iter().filter(|r| !r.outcome.is_good()).count();
    assert_eq!(
        bad,
        0,
        "{bad} of {} corpus entries are not clear (vague, silent, abort, hang or a refused \
         valid base); the table and their messages are printed above (run with --nocapture)",
        runs.len()
    );
}
