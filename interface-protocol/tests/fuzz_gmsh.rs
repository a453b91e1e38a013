//! Property-based fuzzing of the shared gmsh 4.1 reader (`io::gmsh::parse`): random bytes,
//! random bytes behind a valid ASCII or binary `$MeshFormat`, and mutations of the committed
//! fixtures of both solvers (ASCII and binary: a byte flipped, a range deleted or duplicated,
//! a number token replaced by an edge value, the file cut short). Nothing may panic; every error
//! names the file and a line (or a byte offset in binary data); what it accepts is consistent
//! (every node index in range, one tag and position per element).
//!
//! The reader is behind the `io` feature:
//! `cargo test --release -p interface-protocol --features io --test fuzz_gmsh` runs 256 cases
//! per property; `PROPTEST_CASES=100000 bash scripts/fuzz-long` runs the long opt-in campaign.
#![cfg(feature = "io")]

use interface_protocol::io::gmsh::{self, ElementType, GmshError, Msh};
use proptest::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

mod common;
use common::fuzz::{apply, config, msh_files, mutation, panic_message};

/// The file name errors must name.
const FILE: &str = "fuzz.msh";

/// The committed `.msh` fixtures of both solvers, read once.
fn fixtures() -> &'static [Vec<u8>] {
    static FIXTURES: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    FIXTURES.get_or_init(|| {
        msh_files(&["fluid-solver/tests/fixtures", "structure-solver/tests/fixtures"])
    })
}

/// Element types a solver might read: the fluid's and the structure's, or every known one.
fn acceptor(kind: u8) -> impl Fn(ElementType) -> Result<(), String> {
    move |t: ElementType| match kind % 3 {
        0 => Ok(()),
        1 if [2, 3, 4, 5, 6, 7, 15, 1].contains(&t.code) => Ok(()),
        2 if [1, 2, 3, 4, 15].contains(&t.code) => Ok(()),
        _ => Err(format!("element type {} is not read here", t.code)),
    }
}

/// Parses `bytes`, catching a panic, and judges the result.
fn check(bytes: &[u8], kind: u8) -> Result<(), TestCaseError> {
    let result = catch_unwind(AssertUnwindSafe(|| gmsh::parse(bytes, FILE, acceptor(kind))));
    match result {
        Err(panic) => {
            let msg = panic_message(&*panic);
            Err(TestCaseError::fail(format!(
                "gmsh::parse panicked ({msg}) on {} bytes: {:?}",
                bytes.len(),
                String::from_utf8_lossy(&bytes[..bytes.len().min(2000)])
            )))
        }
        Ok(Err(e)) => names_where(&e, bytes),
        Ok(Ok(msh)) => consistent(&msh),
    }
}

fn names_where(e: &GmshError, bytes: &[u8]) -> Result<(), TestCaseError> {
    let shown = e.to_string();
    prop_assert!(
        e.file == FILE && shown.starts_with(FILE),
        "the error does not name the file: {shown}"
    );
    let Some(at) = e.at else {
        return Err(TestCaseError::fail(format!("the error names no place in the file: {shown}")));
    };
    let lines = 1 + bytes.iter().filter(|&&b| b == b'\n').count();
    prop_assert!(
        at.byte <= bytes.len() && at.line >= 1 && at.line <= lines,
        "byte {} / line {} is outside the {}-byte, {lines}-line input: {shown}",
        at.byte,
        at.line,
        bytes.len()
    );
    let expected = if e.binary {
        format!("{FILE}: byte {} (line {})", at.byte, at.line)
    } else {
        format!("{FILE}:{}", at.line)
    };
    prop_assert!(shown.starts_with(&expected), "`{shown}` does not start with `{expected}`");
    Ok(())
}

fn consistent(msh: &Msh) -> Result<(), TestCaseError> {
    prop_assert_eq!(msh.coords.len(), msh.node_tags.len());
    prop_assert!(msh.coords.iter().flatten().all(|v| v.is_finite()), "non-finite coordinates");
    for b in &msh.blocks {
        prop_assert_eq!(b.tags.len(), b.positions.len());
        prop_assert_eq!(b.connectivity.len(), b.tags.len() * b.kind.n_nodes);
        prop_assert!(
            b.connectivity.iter().all(|&i| (i as usize) < msh.coords.len()),
            "a node index past the {} nodes",
            msh.coords.len()
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..1024), kind in any::<u8>()) {
        check(&bytes, kind)?;
    }

    #[test]
    fn random_bytes_after_a_valid_header(
        binary in any::<bool>(),
        tail in prop::collection::vec(any::<u8>(), 0..1024),
        kind in any::<u8>(),
    ) {
        let mut bytes: Vec<u8> = if binary {
            b"$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n".to_vec()
        } else {
            b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n".to_vec()
        };
        bytes.extend_from_slice(&tail);
        check(&bytes, kind)?;
    }

    #[test]
    fn random_sections_after_a_valid_header(
        sections in prop::collection::vec(
            (prop::sample::select(&["Nodes", "Elements", "Entities", "PhysicalNames", "Other"][..]),
             "[0-9 \\-\n\"a-z.]{0,80}"),
            0..5,
        ),
        kind in any::<u8>(),
    ) {
        let mut text = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
        for (name, body) in &sections {
            text.push_str(&format!("${name}\n{body}\n$End{name}\n"));
        }
        check(text.as_bytes(), kind)?;
    }

    #[test]
    fn mutated_fixtures(
        pick in any::<prop::sample::Index>(),
        edits in prop::collection::vec(mutation(), 1..4),
        kind in any::<u8>(),
    ) {
        let mut bytes = pick.get(fixtures()).clone();
        for m in &edits {
            bytes = apply(&bytes, m);
        }
        check(&bytes, kind)?;
    }
}
