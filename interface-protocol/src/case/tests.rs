use super::*;

fn parse(text: &str) -> Result<Case, CaseError> {
    Case::parse(text, Path::new("cases/t/case.toml"), &[])
}

#[test]
fn defaults_fill_missing_sections() {
    let c = parse("[coupling]\nscheme = \"A6\"\ndt = 0.5\nt_end = 1.0\n").unwrap();
    assert_eq!(c.coupling.scheme, Scheme::A6);
    assert_eq!(c.coupling.timeout_s, 60.0);
    assert!(c.fluid.is_none());
}

#[test]
fn unknown_key_names_line_and_field() {
    let e = parse("[coupling]\ndt = 1e-3\nsheme = \"C0\"\n").unwrap_err();
    assert_eq!(e.location.map(|l| l.0), Some(3), "{e}");
    assert_eq!(e.field.as_deref(), Some("coupling.sheme"), "{e}");
    assert!(e.to_string().contains("cases/t/case.toml:3:"), "{e}");
}

#[test]
fn wrong_type_names_line_and_field() {
    let e = parse("[coupling]\n\ndt = \"fast\"\n").unwrap_err();
    assert_eq!(e.location.map(|l| l.0), Some(3), "{e}");
    assert_eq!(e.field.as_deref(), Some("coupling.dt"), "{e}");
}

#[test]
fn bad_enum_value_lists_the_choices() {
    let e = parse("[coupling]\nscheme = \"C1\"\n").unwrap_err();
    assert_eq!(e.location.map(|l| l.0), Some(2), "{e}");
    assert!(e.message.contains("C0") && e.message.contains("A6"), "{e}");
}

#[test]
fn missing_field_names_it() {
    let e = parse("[fluid.piston]\narea = 1.0\np0 = 1e5\nrho0 = 1.2\n").unwrap_err();
    assert!(e.message.contains("c0"), "{e}");
}

#[test]
fn validation_errors_locate_the_key() {
    let e = parse("[coupling]\ndt = -1.0\n").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("coupling.dt"));
    assert_eq!(e.location.map(|l| l.0), Some(2), "{e}");
}

#[test]
fn overrides_change_values_and_the_hash() {
    let text = "[coupling]\ndt = 1e-3\n";
    let a = Case::parse(text, Path::new("c.toml"), &[]).unwrap();
    let b = Case::parse(text, Path::new("c.toml"), &["coupling.dt=2e-3".into()]).unwrap();
    assert_eq!(b.coupling.dt, 2e-3);
    assert_ne!(a.hash(), b.hash());
    let e = Case::parse(text, Path::new("c.toml"), &["coupling.dt=\"x\"".into()]).unwrap_err();
    assert!(e.message.contains("--set"), "{e}");
}

/// The commented example of `structure.rs`'s module documentation.
fn structure_example() -> String {
    let src = include_str!("structure.rs");
    let start = src.find("//! ```toml\n").unwrap() + "//! ```toml\n".len();
    let end = start + src[start..].find("//! ```\n").unwrap();
    src[start..end].lines().map(|l| l.trim_start_matches("//!").trim_start()).fold(
        String::new(),
        |mut s, l| {
            s.push_str(l);
            s.push('\n');
            s
        },
    )
}

#[test]
fn the_documented_structure_example_parses() {
    let c = parse(&structure_example()).unwrap();
    let s = c.structure.unwrap();
    assert_eq!(
        s.mesh,
        Some(StructureMesh::Rectangle { lx: 1.0, ly: 0.1, nx: 24, ny: 2, triangles: false })
    );
    assert_eq!(s.materials["steel"].sigma_y, Some(250e6));
    assert_eq!(s.parts[0].element, ElementType::Bt4);
    assert_eq!(s.bc[0].fixed.len(), 6);
    assert_eq!(s.loads[0].curve, Some(CurveSpec::Ramp(RampCurve { ramp: 1e-3 })));
    assert!(matches!(
        s.loads[0].kind(),
        Some(LoadKind::Point { set: "tip", dof: Dof::Uz, value: 10.0 })
    ));
    assert_eq!(s.integrator(), Integrator::CentralDifference);
}

#[test]
fn structure_generators_curves_and_static_settings_parse() {
    let text = r#"[structure]
mesh = { generator = "hemisphere", radius = 10.0, n_theta = 8, n_phi = 8, phi_deg = [18.0, 90.0] }
integrator = "static"
steps = 5
control = { point = [10.0, 0.0, 0.0], dof = "ux", value = -1.0 }
material = { e = 6.825e7, nu = 0.3, rho = 1.0 }
thickness = 0.04
element = "shell"
[[structure.bc]]
set = "v0"
symmetry = "z"
[[structure.bc]]
set = "u0"
prescribed = { dof = "ry", value = 0.1, curve = { table = [[0.0, 0.0], [1.0, 1.0]] } }
[[structure.loads]]
gravity = [0.0, 0.0, -9.81]
curve = "constant"
[[structure.loads]]
pressure = 1e3
set = "all"
"#;
    let s = parse(text).unwrap().structure.unwrap();
    assert!(matches!(s.mesh, Some(StructureMesh::Sphere { n_phi: 8, phi_deg: [18.0, 90.0], .. })));
    assert_eq!(s.control.as_ref().unwrap().dof, Dof::Ux);
    assert_eq!(s.bc[0].symmetry, Some(Symmetry::Axis(Axis::Z)));
    assert_eq!(s.bc[1].prescribed.as_ref().unwrap().dof.index(), 4);
    assert!(matches!(s.loads[1].kind(), Some(LoadKind::Pressure { set: Some("all"), p: 1e3 })));
}

/// The error of `text` as `file:line:col: field ...`: its line, field and message.
fn structure_error(text: &str) -> (Option<usize>, String, String) {
    let e = parse(text).unwrap_err();
    (e.location.map(|l| l.0), e.field.clone().unwrap_or_default(), e.to_string())
}

#[test]
fn structure_errors_name_the_field_line_and_choices() {
    let base =
        "[structure]\nmesh = { generator = \"rectangle\", lx = 1.0, ly = 1.0, nx = 2, ny = 2 }\n\
                material = { e = 1.0, nu = 0.3, rho = 1.0 }\n";
    // an unknown element lists the families
    let (line, field, msg) = structure_error(&format!(
        "{base}[[structure.parts]]\nelement = \"quad\"\nthickness = 0.1\n"
    ));
    assert_eq!((line, field.as_str()), (Some(5), "structure.parts[0].element"), "{msg}");
    assert!(msg.contains("bt4") && msg.contains("mitc4") && msg.contains("tet4"), "{msg}");
    // an unknown generator lists the generators
    let (_, field, msg) =
        structure_error("[structure]\nmesh = { generator = \"disc\", radius = 1.0 }\n");
    assert_eq!(field, "structure.mesh.generator", "{msg}");
    assert!(msg.contains("annulus") && msg.contains("gmsh"), "{msg}");
    // a curve that is none of the forms says what a curve is
    let (line, field, msg) = structure_error(&format!(
        "{base}[[structure.loads]]\nset = \"all\"\ndof = \"uz\"\nvalue = 1.0\ncurve = \"sine\"\n"
    ));
    assert_eq!((line, field.as_str()), (Some(8), "structure.loads[0].curve"), "{msg}");
    assert!(msg.contains("ramp") && msg.contains("table"), "{msg}");
    // a table going back in time: the field of the second load, on its line
    let (line, field, msg) = structure_error(&format!(
        "{base}[[structure.loads]]\ngravity = [0.0, 0.0, -1.0]\n[[structure.loads]]\n\
         pressure = 1.0\ncurve = {{ table = [[1.0, 0.0], [0.5, 1.0]] }}\n"
    ));
    assert_eq!(field, "structure.loads[1].curve.table", "{msg}");
    assert_eq!(line, Some(8), "{msg}");
    // two kinds of condition in one bc entry
    let (line, field, msg) = structure_error(&format!(
        "{base}[[structure.bc]]\nset = \"u0\"\nfixed = [\"ux\"]\n[[structure.bc]]\nset = \"u1\"\n\
         fixed = [\"uz\"]\nsymmetry = \"x\"\n"
    ));
    assert_eq!((line, field.as_str()), (Some(7), "structure.bc[1]"), "{msg}");
    assert!(msg.contains("exactly one of"), "{msg}");
    // an unknown material names the known ones
    let (line, field, msg) = structure_error(&format!(
        "{base}[[structure.parts]]\nelement = \"mitc4\"\nmaterial = \"steel\"\nthickness = 0.1\n"
    ));
    assert_eq!((line, field.as_str()), (Some(6), "structure.parts[0].material"), "{msg}");
    assert!(msg.contains("no material \"steel\"; known materials: default"), "{msg}");
    // shells need a thickness, static settings need the static integrator
    let (_, field, _) = structure_error(&format!("{base}[[structure.parts]]\nelement = \"dkt\"\n"));
    assert_eq!(field, "structure.parts[0].thickness");
    let (line, field, _) = structure_error(&format!("{base}steps = 4\n"));
    assert_eq!((line, field.as_str()), (Some(4), "structure.steps"));
    // arc-length bounds
    let (line, field, msg) = structure_error(&format!(
        "{base}integrator = \"static\"\narc_length = {{ initial = 0.1, min = 0.5 }}\n"
    ));
    assert_eq!((line, field.as_str()), (Some(5), "structure.arc_length"), "{msg}");
    assert!(msg.contains("0 < min <= initial <= max"), "{msg}");
}

#[test]
fn gmsh_meshes_declare_coincident_nodes_and_load_steps_are_capped() {
    let gmsh = |extra: &str| {
        let text =
            format!("[structure]\nmesh = {{ generator = \"gmsh\", file = \"m.msh\"{extra} }}\n");
        parse(&text).map(|c| c.structure.unwrap().mesh.unwrap())
    };
    let coincident = |m: StructureMesh| match m {
        StructureMesh::Gmsh { coincident_nodes, .. } => coincident_nodes,
        m => panic!("{m:?}"),
    };
    assert_eq!(coincident(gmsh("").unwrap()), CoincidentNodes::Warn);
    let allowed = gmsh(", coincident_nodes = \"allow\"").unwrap();
    assert_eq!(coincident(allowed), CoincidentNodes::Allow);
    let e = gmsh(", coincident_nodes = \"merge\"").unwrap_err();
    assert!(e.message.contains("warn") && e.message.contains("allow"), "{e}");
    // 10^10 load steps would not end in any reasonable time: refused on its line
    let (line, field, msg) =
        structure_error("[structure]\nintegrator = \"static\"\nsteps = 10000000000\n");
    assert_eq!((line, field.as_str()), (Some(3), "structure.steps"), "{msg}");
    assert!(msg.contains("more than the 1000000000"), "{msg}");
}
