//! Property-based fuzzing of the fluid's gmsh mesh path: the committed fixtures
//! (`tests/fixtures/*.msh`, ASCII and binary) mutated (a byte flipped, a range deleted or
//! duplicated, a number token replaced by an edge value, the file cut short), then read by
//! `mesh::gmsh::read` and built into the median-dual mesh by `Mesh::build`. Nothing may panic;
//! every error names the file and where in it (a line, a byte offset, or the cell, face or node);
//! a mesh that builds has its indices in range and positive finite dual volumes.
//!
//! `cargo test --release -p fluid-solver --test fuzz_mesh` runs 256 cases per property;
//! `PROPTEST_CASES=100000 bash scripts/fuzz-long` runs the long opt-in campaign.

use fluid_solver::mesh::{gmsh, Mesh};
use proptest::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

#[path = "../../interface-protocol/tests/common/fuzz.rs"]
mod fuzz;
use fuzz::{apply, config, msh_files, mutation, panic_message};

/// The file every case is written to (one per test thread), in a folder that lives as long as
/// the test binary.
fn scratch_file() -> PathBuf {
    static DIR: std::sync::OnceLock<tempfile::TempDir> = std::sync::OnceLock::new();
    let dir = DIR.get_or_init(|| tempfile::Builder::new().prefix("fuzz-fluid-").tempdir().unwrap());
    let thread = format!("{:?}", std::thread::current().id());
    let tag: String = thread.chars().filter(char::is_ascii_digit).collect();
    dir.path().join(format!("fuzz{tag}.msh"))
}

fn fixtures() -> &'static [Vec<u8>] {
    static FIXTURES: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    FIXTURES.get_or_init(|| msh_files(&["fluid-solver/tests/fixtures"]))
}

/// The message names the file, and a line (`file:12`), a byte offset, a cell, face or node.
fn names_where(message: &str, file: &Path) -> bool {
    let name = file.file_name().unwrap().to_string_lossy();
    let Some(at) = message.find(name.as_ref()) else { return false };
    let after = &message[at + name.len()..];
    let line = after.strip_prefix(':').is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()));
    line || ["byte ", "cell ", "face ", "node ", "element "].iter().any(|w| message.contains(w))
}

fn check(bytes: &[u8]) -> Result<(), TestCaseError> {
    let path = scratch_file();
    std::fs::write(&path, bytes).expect("write the mutated mesh");
    let result = catch_unwind(AssertUnwindSafe(|| gmsh::read(&path).and_then(Mesh::build)));
    let shown = || String::from_utf8_lossy(&bytes[..bytes.len().min(3000)]).into_owned();
    match result {
        Err(panic) => Err(TestCaseError::fail(format!(
            "reading or building the mesh panicked ({}) on {} bytes: {:?}",
            panic_message(&*panic),
            bytes.len(),
            shown()
        ))),
        Ok(Err(e)) => {
            let message = e.to_string();
            prop_assert!(names_where(&message, &path), "the error does not say where: {message}");
            Ok(())
        }
        Ok(Ok(mesh)) => {
            let n = mesh.n_nodes();
            prop_assert!(
                mesh.edges.iter().flatten().all(|&i| (i as usize) < n),
                "an edge past the nodes"
            );
            prop_assert!(
                mesh.volumes.iter().all(|v| v.is_finite() && *v > 0.0),
                "a dual volume that is not finite and positive in a mesh that built: {:?}",
                mesh.volumes.iter().find(|v| !(v.is_finite() && **v > 0.0))
            );
            for b in &mesh.boundaries {
                prop_assert!(
                    b.nodes.iter().all(|&i| (i as usize) < n),
                    "a boundary node past the nodes"
                );
            }
            Ok(())
        }
    }
}

/// The input the campaign shrank its first panic to: one node of hex 109 of `hex_box.msh`
/// (line 471) replaced by another node of the same hex. The cell keeps a positive volume, and
/// building the dual mesh must refuse it, naming the element, instead of panicking.
#[test]
fn a_hex_listing_a_node_twice_is_refused() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/hex_box.msh"),
    )
    .expect("the hex fixture");
    let line = "109 49 9 2 16 111 61 29 81";
    assert!(text.contains(line), "hex_box.msh changed: update this test");
    let bytes = text.replace(line, "109 49 9 2 2 111 61 29 81").into_bytes();
    if let Err(e) = check(&bytes) {
        panic!("{e}");
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn mutated_fixtures(pick in any::<prop::sample::Index>(), edits in prop::collection::vec(mutation(), 1..4)) {
        let mut bytes = pick.get(fixtures()).clone();
        for m in &edits {
            bytes = apply(&bytes, m);
        }
        check(&bytes)?;
    }

    #[test]
    fn unmutated_fixtures_build(pick in any::<prop::sample::Index>()) {
        check(pick.get::<Vec<u8>>(fixtures()))?;
    }
}
