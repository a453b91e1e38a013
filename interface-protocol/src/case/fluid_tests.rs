//! Named fluids of `[fluid]`: material ids, the background and region fluids, and the errors.

use crate::case::{Case, CaseError, SINGLE_FLUID};
use std::path::Path;

fn parse(text: &str) -> Result<Case, CaseError> {
    Case::parse(text, Path::new("cases/t/case.toml"), &[])
}

const TWO: &str =
    "[fluid.fluids.water]\neos = { kind = \"stiffened_gas\", gamma = 4.4, p_c = 6e8 }\n\
[fluid.fluids.air]\neos = { kind = \"perfect_gas\", gamma = 1.4 }\n";

fn with_initial(initial: &str) -> String {
    format!("{TWO}[fluid.initial]\n{initial}")
}

#[test]
fn named_fluids_get_ids_in_name_order_and_regions_default_to_the_background() {
    let c = parse(&with_initial(
        "fluid = \"water\"\nstate = [1000, 0, 0, 0, 1e5]\nregions = [\
         { region = { shape = \"box\", lo = [0, 0, 0], hi = [1, 1, 1] }, fluid = \"air\", state = [1, 0, 0, 0, 1e5] },\
         { region = { shape = \"sphere\", center = [0, 0, 0], radius = 1 }, state = [1000, 0, 0, 0, 1e5] }]\n",
    ))
    .unwrap();
    let f = c.fluid.unwrap();
    let m = f.materials();
    let names: Vec<&str> = m.iter().map(|m| m.name).collect();
    assert_eq!(names, ["air", "water"]);
    assert_eq!(m[1].eos_field, "fluid.fluids.water.eos");
    assert_eq!(m[1].eos.get("p_c").and_then(|v| v.as_float()), Some(6e8));
    assert_eq!(f.initial_materials(), Some((1, vec![0, 1])));
}

#[test]
fn a_single_eos_is_one_fluid_named_fluid() {
    let text = "[fluid]\neos = { kind = \"perfect_gas\", gamma = 1.4 }\n[fluid.initial]\n\
                state = [1, 0, 0, 0, 1]\n";
    let f = parse(text).unwrap().fluid.unwrap();
    assert_eq!(f.materials().len(), 1);
    assert_eq!(
        (f.materials()[0].name, f.materials()[0].eos_field.as_str()),
        (SINGLE_FLUID, "fluid.eos")
    );
    assert_eq!(f.initial_materials(), Some((0, vec![])));
    // Its name may be given; no other.
    let named = text.replace("state = [1,", "fluid = \"fluid\"\nstate = [1,");
    assert!(parse(&named).is_ok());
    let e = parse(&text.replace("state = [1,", "fluid = \"air\"\nstate = [1,")).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fluid.initial.fluid"), "{e}");
    assert!(e.message.contains("unknown fluid `air`; the case's fluids are: fluid"), "{e}");
}

#[test]
fn eos_and_fluids_together_are_refused() {
    let e = parse(&format!("[fluid]\neos = {{ kind = \"perfect_gas\", gamma = 1.4 }}\n{TWO}"))
        .unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fluid.fluids"), "{e}");
    assert!(e.message.contains("not both"), "{e}");
    assert!(e.location.is_some(), "{e}");
}

#[test]
fn an_unknown_region_fluid_names_the_region_and_the_fluids() {
    let e = parse(&with_initial(
        "fluid = \"air\"\nstate = [1, 0, 0, 0, 1e5]\nregions = [\
         { region = { shape = \"sphere\", center = [0, 0, 0], radius = 1 }, fluid = \"oil\", state = [900, 0, 0, 0, 1e5] }]\n",
    ))
    .unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fluid.initial.regions[0].fluid"), "{e}");
    assert!(e.message.contains("unknown fluid `oil`; the case's fluids are: air, water"), "{e}");
}

#[test]
fn several_fluids_need_a_background_fluid() {
    let e = parse(&with_initial("state = [1, 0, 0, 0, 1e5]\n")).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fluid.initial.fluid"), "{e}");
    assert!(e.message.contains("missing") && e.message.contains("fluid = \"air\""), "{e}");
}

#[test]
fn a_named_fluid_takes_only_an_eos() {
    let e =
        parse("[fluid.fluids.air]\neos = { kind = \"perfect_gas\", gamma = 1.4 }\ngamma = 1.4\n")
            .unwrap_err();
    assert!(e.message.contains("gamma"), "{e}");
    let e = parse("[fluid.fluids.air]\n").unwrap_err();
    assert!(e.message.contains("eos"), "{e}");
}

#[test]
fn fixed_fluid_substeps_are_at_least_one_and_not_with_local_time_steps() {
    let text = "[fluid.time]\nsubsteps = 8\n";
    let t = parse(text).unwrap().fluid.unwrap().time.unwrap();
    assert_eq!((t.substeps, t.t_end), (Some(8), None), "a coupled case needs no fluid t_end");
    let e = parse("[fluid.time]\nsubsteps = 0\n").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fluid.time.substeps"), "{e}");
    assert!(e.message.contains("at least 1"), "{e}");
    let local = "[fluid.numerics]\nlocal_time_step = true\n[fluid.time]\nsubsteps = 4\n";
    let e = parse(local).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fluid.time.substeps"), "{e}");
    assert!(e.message.contains("local_time_step"), "{e}");
}
