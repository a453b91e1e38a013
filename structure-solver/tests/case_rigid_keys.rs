//! The case keys of rigid bodies (`[[structure.rigid_bodies]]`): `reference_set` makes an
//! existing node the reference (no node is added; its own mass joins the body) and `inertia`
//! adds rotary inertia about it; both are checked with errors naming the field.

use std::path::Path;

use interface_protocol::case::Case;
use structure_solver::assembly::RotaryInertia;
use structure_solver::build::build;
use structure_solver::model::Model;

/// A 1 x 1 plate of 2 x 2 shells whose right edge is one rigid body, with `body` appended to
/// its `[[structure.rigid_bodies]]` entry.
fn case(body: &str) -> String {
    format!(
        r#"[structure]
mesh = {{ generator = "rectangle", lx = 1.0, ly = 1.0, nx = 2, ny = 2 }}
material = {{ e = 1e6, nu = 0.3, rho = 1.0 }}
element = "shell"
thickness = 0.1
integrator = "newmark"
dt = 1e-3
t_end = 1e-2
[structure.sets]
edge = {{ min = [0.999, -1, -1], max = [1.001, 2, 1] }}
corner = {{ min = [0.999, 0.999, -1], max = [1.001, 1.001, 1] }}
pair = {{ min = [0.999, 0.4, -1], max = [1.001, 2, 1] }}
[[structure.rigid_bodies]]
set = "edge"
{body}
"#
    )
}

fn built(text: &str) -> anyhow::Result<structure_solver::build::Structure> {
    let case = Case::parse(text, Path::new("case.toml"), &[])?;
    build(&case, RotaryInertia::Physical)
}

#[test]
fn an_existing_reference_node_and_added_inertia_reach_the_body() {
    let plain = built(&case("")).unwrap();
    let with = built(&case(
        "reference_set = \"corner\"\nmass = 0.5\ninertia = [[0.1, 0.0, 0.02], [0.0, 0.2, 0.0], [0.02, 0.0, 0.3]]",
    ))
    .unwrap();
    // the mass centre reference adds a node, the existing one does not
    assert_eq!(plain.model.n_nodes(), 10);
    assert_eq!(with.model.n_nodes(), 9);
    let corner = with.mesh.node_set("corner").unwrap()[0];
    assert_eq!(with.mesh.node_set("edge_reference").unwrap(), &[corner]);
    let body = &with.model.rigid_bodies()[0];
    assert_eq!(body.master, corner);
    assert_eq!(body.slaves.len(), 2);
    // the master's mass: the edge's three nodes (a quarter of the plate's 0.1) plus 0.5; its
    // rotary inertia about z: the nodes' and the added 0.3
    let m = with.model.lumped_mass();
    let d = 6 * corner;
    println!("reference at node {corner}: mass {:.6}, I_zz {:.6}", m[d], m[d + 5]);
    assert!((m[d] - (0.025 + 0.5)).abs() < 1e-12, "mass {}", m[d]);
    let nodal_izz = plain.model.lumped_mass()[6 * 9 + 5];
    assert!(m[d + 5] > 0.3 && nodal_izz > 0.0, "I_zz {} (nodal {nodal_izz})", m[d + 5]);
}

#[test]
fn bad_rigid_body_keys_name_their_field() {
    let err = |body: &str| format!("{:#}", built(&case(body)).err().expect("refused"));
    let e = err("reference_set = \"pair\"");
    assert!(e.contains("structure.rigid_bodies[0].reference_set") && e.contains("one node"), "{e}");
    let e = err("reference_set = \"corner\"\nreference = [1.0, 1.0, 0.0]");
    assert!(e.contains("structure.rigid_bodies[0].reference_set") && e.contains("not both"), "{e}");
    let e = err("inertia = [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]");
    assert!(e.contains("structure.rigid_bodies[0].inertia") && e.contains("symmetric"), "{e}");
    let e = err("inertia = [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]");
    assert!(e.contains("structure.rigid_bodies[0].inertia"), "{e}");
    let e = err("reference_set = \"nowhere\"");
    assert!(e.contains("structure.rigid_bodies[0].reference_set") && e.contains("nowhere"), "{e}");
}
