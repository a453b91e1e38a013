//! Property-based fuzzing of the case parser (`Case::parse`): random bytes, random printable
//! text, TOML-shaped token soup, and mutations of every `cases/*/case.toml` (a line deleted,
//! duplicated or replaced, a byte flipped, the text cut short), and random `--set` overrides. Nothing may panic, and every error names the file and where in it: a line and
//! column, or a field.
//!
//! `cargo test --release -p interface-protocol --test fuzz_case` runs 256 cases per property;
//! `PROPTEST_CASES=100000 bash scripts/fuzz-long` runs the long opt-in campaign.

use interface_protocol::case::{Case, CaseError};
use proptest::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

mod common;
use common::fuzz::{config, panic_message};

/// The file name errors must start with.
const FILE: &str = "fuzz/case.toml";

/// Every committed case file, read once.
fn cases() -> &'static [String] {
    static CASES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    CASES.get_or_init(read_cases)
}

fn read_cases() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases");
    let mut texts: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .flatten()
        .filter_map(|d| {
            let p = d.path().join("case.toml");
            Some((p.display().to_string(), std::fs::read_to_string(&p).ok()?))
        })
        .collect();
    texts.sort();
    assert!(!texts.is_empty(), "no cases/*/case.toml under {}", dir.display());
    texts.into_iter().map(|(_, t)| t).collect()
}

/// Parses `text` with `overrides`, catching a panic; the verdict on the result.
fn check(text: &str, overrides: &[String]) -> Result<(), TestCaseError> {
    let result = catch_unwind(AssertUnwindSafe(|| Case::parse(text, Path::new(FILE), overrides)));
    match result {
        Err(panic) => {
            let msg = panic_message(&*panic);
            Err(TestCaseError::fail(format!(
                "Case::parse panicked ({msg}) on {text:?} with overrides {overrides:?}"
            )))
        }
        Ok(Ok(_)) => Ok(()),
        Ok(Err(e)) => names_where(&e, text, overrides),
    }
}

/// An error names the file, and a line and column or a field.
fn names_where(e: &CaseError, text: &str, overrides: &[String]) -> Result<(), TestCaseError> {
    let shown = e.to_string();
    prop_assert!(
        shown.starts_with(FILE),
        "the error does not start with the file name: {shown}\ninput: {text:?}\noverrides: \
         {overrides:?}"
    );
    prop_assert!(
        e.location.is_some() || e.field.as_deref().is_some_and(|f| !f.is_empty()),
        "the error names neither a line nor a field: {shown}\ninput: {text:?}\noverrides: \
         {overrides:?}"
    );
    if let Some((line, col)) = e.location {
        let lines = text.split('\n').count();
        prop_assert!(
            line >= 1 && line <= lines && col >= 1,
            "line {line}, column {col} is not in the {lines}-line input: {shown}\ninput: {text:?}"
        );
    }
    Ok(())
}

/// Keys of the schema, for overrides and token soup.
const KEYS: &[&str] = &[
    "case.name",
    "coupling.dt",
    "coupling.t_end",
    "coupling.scheme",
    "coupling.timeout_s",
    "output.probes_every",
    "output.dir",
    "fluid.command",
    "fluid.piston.area",
    "fluid.piston.normal",
    "fluid.mesh.box.cells",
    "fluid.numerics.cfl",
    "fluid.time.t_end",
    "fluid.eos",
    "structure.rigid.mass",
    "structure.rigid.dofs",
    "structure.mesh",
    "structure.dt",
    "structure.safety",
    "structure.t_end",
    "structure.material.nu",
    "structure.bc",
    "x",
    "",
    "coupling",
    "coupling.dt.x",
    "fluid.probes",
];

/// Values of every TOML type and some edge numbers.
const VALUES: &[&str] = &[
    "1e-4",
    "0",
    "-1",
    "nan",
    "inf",
    "-inf",
    "1e-300",
    "1e300",
    "18446744073709551615",
    "-9223372036854775808",
    "\"C0\"",
    "\"\"",
    "true",
    "[1, 2, 3]",
    "[]",
    "{ kind = \"perfect_gas\", gamma = 1.4 }",
    "{}",
    "[[1.0, 2.0]]",
    "1979-05-27T07:32:00Z",
    "\"\u{e9}\u{1f600}\"",
    "=",
    "[",
    "{",
];

fn overrides() -> impl Strategy<Value = Vec<String>> {
    prop::collection::vec(
        prop_oneof![
            (prop::sample::select(KEYS), prop::sample::select(VALUES))
                .prop_map(|(k, v)| format!("{k}={v}")),
            "[ -~]{0,24}",
        ],
        0..3,
    )
}

/// Lines made of schema pieces: table headers, keys, values and stray punctuation.
fn token_soup() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        prop::sample::select(KEYS).prop_map(|k| format!("[{k}]\n")),
        prop::sample::select(KEYS).prop_map(|k| format!("[[{k}]]\n")),
        (prop::sample::select(KEYS), prop::sample::select(VALUES)).prop_map(|(k, v)| {
            let key = k.rsplit('.').next().unwrap_or(k);
            format!("{key} = {v}\n")
        }),
        prop::sample::select(VALUES).prop_map(|v| v.to_string()),
        prop::sample::select(
            &["\n", " ", "#", "\"", "'", "'''", "\"\"\"", ",", ".", "\r\n", "\t"][..]
        )
        .prop_map(|s| s.to_string()),
    ];
    prop::collection::vec(piece, 0..40).prop_map(|p| p.concat())
}

/// A mutation of a text.
#[derive(Debug, Clone)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    ReplaceLine(usize, String),
    FlipByte(usize, u8),
    Truncate(usize),
    Insert(usize, String),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), prop_oneof!["[ -~]{0,40}", token_soup()])
            .prop_map(|(k, s)| Mutation::ReplaceLine(k, s)),
        (any::<usize>(), any::<u8>()).prop_map(|(k, b)| Mutation::FlipByte(k, b)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), prop::sample::select(VALUES))
            .prop_map(|(k, v)| Mutation::Insert(k, v.into())),
    ]
}

fn apply(text: &str, m: &Mutation) -> String {
    let mut lines: Vec<String> = text.split('\n').map(str::to_string).collect();
    let n = lines.len().max(1);
    match m {
        Mutation::DeleteLine(k) => {
            lines.remove(k % lines.len());
        }
        Mutation::DuplicateLine(k) => {
            let l = lines[k % lines.len()].clone();
            lines.insert(k % lines.len(), l);
        }
        Mutation::ReplaceLine(k, s) => lines[k % n] = s.clone(),
        Mutation::FlipByte(k, b) => {
            let mut bytes = text.as_bytes().to_vec();
            if !bytes.is_empty() {
                let i = k % bytes.len();
                bytes[i] ^= b | 1;
            }
            return String::from_utf8_lossy(&bytes).into_owned();
        }
        Mutation::Truncate(k) => {
            let bytes = text.as_bytes();
            let cut = k % (bytes.len() + 1);
            return String::from_utf8_lossy(&bytes[..cut]).into_owned();
        }
        Mutation::Insert(k, v) => {
            let bytes = text.as_bytes();
            let at = k % (bytes.len() + 1);
            let mut out = bytes[..at].to_vec();
            out.extend_from_slice(v.as_bytes());
            out.extend_from_slice(&bytes[at..]);
            return String::from_utf8_lossy(&out).into_owned();
        }
    }
    lines.join("\n")
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        check(&String::from_utf8_lossy(&bytes), &[])?;
    }

    #[test]
    fn random_printable_text(text in "[ -~\n\t]{0,512}") {
        check(&text, &[])?;
    }

    #[test]
    fn token_soup_text(text in token_soup()) {
        check(&text, &[])?;
    }

    #[test]
    fn mutated_cases(
        pick in any::<prop::sample::Index>(),
        edits in prop::collection::vec(mutation(), 1..4),
    ) {
        let mut text = pick.get(cases()).clone();
        for m in &edits {
            text = apply(&text, m);
        }
        check(&text, &[])?;
    }

    /// `--set` overrides, on the committed cases and on token soup.
    #[test]
    fn random_overrides(
        pick in any::<prop::sample::Index>(),
        soup in prop::option::of(token_soup()),
        sets in overrides(),
    ) {
        let text = soup.unwrap_or_else(|| pick.get::<String>(cases()).clone());
        check(&text, &sets)?;
    }
}
