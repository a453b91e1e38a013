//! `fsi check CASE`: parse and validate a case without running it, and say what a run would do.

use crate::scheme::{scheme_name, SchemeSettings, Sequencer};
use crate::supervise::resolve_program;
use interface_protocol::case::Case;
use interface_protocol::messages::Role;
use std::fmt::Write;
use std::path::Path;

/// The case's summary, or its first error (file:line:column, field, what was expected).
pub fn check(case_file: &Path, overrides: &[String]) -> anyhow::Result<String> {
    let case = Case::load(case_file, overrides)?;
    let s = SchemeSettings::of_case(&case);
    let seq = Sequencer::new(s).map_err(|e| anyhow::anyhow!("{}: {e}", case_file.display()))?;
    let mut out = String::new();
    let w = &mut out;
    writeln!(w, "{}: ok", case_file.display())?;
    writeln!(w, "  case       {}", case.case.name)?;
    if !case.case.description.is_empty() {
        writeln!(w, "  about      {}", case.case.description)?;
    }
    writeln!(
        w,
        "  coupling   {}, dt {:e} s, t_end {:e} s: {} steps (last {:e} s), timeout {} s",
        scheme_name(s.scheme),
        s.dt,
        s.t_end,
        s.n_steps,
        round12(seq.step_dt(s.n_steps.saturating_sub(1))),
        case.coupling.timeout_s
    )?;
    let fluid =
        case.fluid.as_ref().map(|f| f.command()).unwrap_or_else(|| vec!["fluid-solver".into()]);
    let structure = case
        .structure
        .as_ref()
        .map(|s| s.command())
        .unwrap_or_else(|| vec!["structure-solver".into()]);
    for (role, cmd) in [(Role::Fluid, fluid), (Role::Structure, structure)] {
        let found = match cmd.first().map(|p| resolve_program(p, role)) {
            Some(Ok(p)) => format!("({})", p.display()),
            Some(Err(_)) => "(not found next to fsi or on PATH)".to_string(),
            None => "(empty command)".to_string(),
        };
        writeln!(w, "  {:<10} {} {found}", role.name(), cmd.join(" "))?;
    }
    let o = &case.output;
    writeln!(
        w,
        "  output     {}; fields every {}, probes every {}, checkpoints every {}",
        o.dir.as_deref().unwrap_or("runs/<case>-<timestamp>"),
        o.fields_every,
        o.probes_every,
        o.checkpoint_every
    )?;
    writeln!(w, "  case hash  {:016x}", case.hash())?;
    Ok(out)
}

/// `v` to 12 significant digits, so a last step of 1e-3 does not print as 1.0000000000000009e-3.
fn round12(v: f64) -> f64 {
    format!("{v:.11e}").parse().unwrap_or(v)
}
