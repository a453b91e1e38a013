use super::*;

fn parse(text: &str) -> Result<Case, CaseError> {
    Case::parse(text, Path::new("cases/t/case.toml"), &[])
}

#[test]
fn defaults_fill_missing_sections() {
    let c = parse("[coupling]\nscheme = \"A6\"\ndt = 0.5\n").unwrap();
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
