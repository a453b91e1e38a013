//! Property-based fuzzing of the structure's gmsh reader (`mesh::gmsh::parse`, with its validity
//! pass): the committed fixtures of both solvers (ASCII and binary) mutated (a byte flipped, a
//! range deleted or duplicated, a number token replaced by an edge value, the file cut short).
//! Nothing may panic; every error names the file and a line or a byte offset; a mesh it accepts
//! has every cell and set index in range.
//!
//! `cargo test --release -p structure-solver --test fuzz_mesh` runs 256 cases per property;
//! `PROPTEST_CASES=100000 bash scripts/fuzz-long` runs the long opt-in campaign.

use proptest::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use structure_solver::mesh::gmsh;

#[path = "../../interface-protocol/tests/common/fuzz.rs"]
mod fuzz;
use fuzz::{apply, config, msh_files, mutation, panic_message};

const FILE: &str = "fuzz.msh";

fn fixtures() -> &'static [Vec<u8>] {
    static FIXTURES: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    FIXTURES.get_or_init(|| {
        msh_files(&["structure-solver/tests/fixtures", "fluid-solver/tests/fixtures"])
    })
}

/// `fuzz.msh:12...` or `fuzz.msh: byte N (line L)...`.
fn names_where(message: &str) -> bool {
    message.strip_prefix(FILE).is_some_and(|r| {
        r.strip_prefix(':').is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
            || r.starts_with(": byte ")
    })
}

fn check(bytes: &[u8]) -> Result<(), TestCaseError> {
    let result = catch_unwind(AssertUnwindSafe(|| gmsh::parse(bytes, FILE)));
    match result {
        Err(panic) => Err(TestCaseError::fail(format!(
            "gmsh::parse panicked ({}) on {} bytes: {:?}",
            panic_message(&*panic),
            bytes.len(),
            String::from_utf8_lossy(&bytes[..bytes.len().min(3000)])
        ))),
        Ok(Err(e)) => {
            let message = e.to_string();
            prop_assert!(names_where(&message), "the error does not say where: {message}");
            Ok(())
        }
        Ok(Ok(mesh)) => {
            let n = mesh.nodes.len();
            for c in &mesh.cells {
                prop_assert_eq!(c.nodes.len(), c.kind.n_nodes());
                prop_assert!(c.nodes.iter().all(|&i| i < n), "a cell node past the {} nodes", n);
            }
            for (name, set) in &mesh.node_sets {
                prop_assert!(set.iter().all(|&i| i < n), "node set {} past the nodes", name);
            }
            for (name, set) in &mesh.cell_sets {
                prop_assert!(
                    set.iter().all(|&c| c < mesh.cells.len()),
                    "cell set {} past the cells",
                    name
                );
            }
            Ok(())
        }
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
}
