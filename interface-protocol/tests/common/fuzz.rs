//! What the fuzz tests share: the proptest settings (`PROPTEST_CASES`, no regression files in
//! the source tree), the text of a caught panic, the committed gmsh fixtures, and mutations of a
//! file's bytes (a byte flipped, a range deleted or duplicated, a whitespace-separated token
//! replaced by an edge value, the file cut short). Used by the fuzz tests here and included by
//! path by the mesh fuzz tests of both solvers.
#![allow(dead_code)]

use proptest::prelude::*;
use proptest::test_runner::Config;
use std::path::Path;

/// `PROPTEST_CASES` cases (default 256) per property; a failure prints its shrunk input and
/// writes no regression file.
pub fn config() -> Config {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256);
    Config { cases, failure_persistence: None, ..Config::default() }
}

/// The message of a panic caught by `catch_unwind`.
pub fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_default()
}

/// The `.msh` files of `dirs` (relative to the workspace root), sorted by path.
pub fn msh_files(dirs: &[&str]) -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in dirs {
        let dir = root.join(dir);
        for e in std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
            .flatten()
        {
            if e.path().extension().is_some_and(|x| x == "msh") {
                files.push((e.path(), std::fs::read(e.path()).expect("a fixture")));
            }
        }
    }
    files.sort();
    assert!(!files.is_empty(), "no .msh files in {dirs:?}");
    files.into_iter().map(|(_, b)| b).collect()
}

/// A mutation of a file's bytes.
#[derive(Debug, Clone)]
pub enum Mutation {
    Flip(usize, u8),
    Delete(usize, usize),
    Duplicate(usize, usize),
    Truncate(usize),
    /// Replace the k-th whitespace-separated token by an edge value.
    Token(usize, &'static str),
}

const EDGE: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "4",
    "8",
    "99",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "9223372036854775807",
    "-9223372036854775808",
    "1e308",
    "nan",
    "inf",
    "",
    "$EndNodes",
    "$Elements",
    "\"",
    "4.1",
    "2.2",
];

pub fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(k, b)| Mutation::Flip(k, b)),
        (any::<usize>(), 1usize..64).prop_map(|(k, n)| Mutation::Delete(k, n)),
        (any::<usize>(), 1usize..64).prop_map(|(k, n)| Mutation::Duplicate(k, n)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), prop::sample::select(EDGE)).prop_map(|(k, t)| Mutation::Token(k, t)),
    ]
}

pub fn apply(bytes: &[u8], m: &Mutation) -> Vec<u8> {
    let mut b = bytes.to_vec();
    let len = b.len().max(1);
    match *m {
        Mutation::Flip(k, x) => {
            if !b.is_empty() {
                b[k % len] ^= x | 1;
            }
        }
        Mutation::Delete(k, n) => {
            let at = k % (b.len() + 1);
            b.drain(at..(at + n).min(b.len()));
        }
        Mutation::Duplicate(k, n) => {
            let at = k % (b.len() + 1);
            let piece = b[at..(at + n).min(b.len())].to_vec();
            b.splice(at..at, piece);
        }
        Mutation::Truncate(k) => b.truncate(k % (b.len() + 1)),
        Mutation::Token(k, t) => {
            let starts: Vec<usize> = (0..b.len())
                .filter(|&i| {
                    !b[i].is_ascii_whitespace() && (i == 0 || b[i - 1].is_ascii_whitespace())
                })
                .collect();
            if !starts.is_empty() {
                let s = starts[k % starts.len()];
                let e = (s..b.len()).find(|&i| b[i].is_ascii_whitespace()).unwrap_or(b.len());
                b.splice(s..e, t.bytes());
            }
        }
    }
    b
}
