//! The every-step check that the body's state and the loads it receives are finite: a NaN or an
//! infinity fails the step at once, naming the quantity, the DOF or wet node, the time and the
//! step, and saying when the step is above the stable one (the usual cause).

use crate::model::Body;
use crate::setup::above_stable_step;
use interface_protocol::io::finite::FiniteScan;
use interface_protocol::messages::NodeLoad;
use interface_protocol::participant::{failure_code, Failure};

/// Where in the run a check happens.
#[derive(Debug, Clone, Copy)]
pub struct At {
    /// Time the checked values stand for [s].
    pub t: f64,
    /// Coupling step (0-based), as in the command.
    pub step: u64,
    /// Length of this coupling step [s].
    pub dt: f64,
    /// The stable step of the integrator [s].
    pub dt_stable: f64,
}

/// `Ok` if every DOF value of `values` is finite; else a `Failed` naming `field`
/// ("displacement", ...), the DOF, time and step.
pub fn check_dofs(body: &Body, field: &str, values: &[f64], at: At) -> Result<(), Failure> {
    let Some(bad) = values.first_non_finite() else { return Ok(()) };
    let mut message = format!(
        "the rigid body's {field} of DOF \"{}\" is {} at t = {} (coupling step {})",
        body.dof_name(bad.index),
        bad.value,
        short(at.t),
        at.step
    );
    match above_stable_step(at.dt, at.dt_stable, body) {
        Some(why) => message += &format!(": the coupling step {} s diverged; {why}", short(at.dt)),
        None => message += ": the integration diverged",
    }
    Err(Failure::new(failure_code::SOLVER, message))
}

/// `Ok` if every nodal load is finite; else a `Failed` naming the wet node and component.
pub fn check_loads(loads: &[NodeLoad], at: At) -> Result<(), Failure> {
    let bad =
        loads.iter().enumerate().find_map(|(i, l)| l.f[..].first_non_finite().map(|b| (i, b)));
    let Some((node, b)) = bad else { return Ok(()) };
    Err(Failure::new(
        failure_code::SOLVER,
        format!(
            "the fluid sent a non-finite load {} (component {}) on wet node {node} at t = {} \
             (coupling step {})",
            b.value,
            ["x", "y", "z"][b.index],
            short(at.t),
            at.step
        ),
    ))
}

/// `x` to 7 significant digits, trailing zeros dropped: `1.098e1`, `3e-2` (times and steps
/// computed by sums carry rounding noise a reader does not need).
pub fn short(x: f64) -> String {
    let text = format!("{x:.6e}");
    match text.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use interface_protocol::case::RigidBody;

    fn body() -> Body {
        let r: RigidBody = toml::from_str(
            "mass = 10.0\ndofs = [\"x\", \"rz\"]\ninertia = [1.0, 1.0, 1.0]\n\
             stiffness = [1e5, 1.0]",
        )
        .unwrap();
        Body::new(&r)
    }

    #[test]
    fn names_the_dof_time_step_and_the_stable_step() {
        let b = body();
        let at = At { t: 0.3, step: 9, dt: 0.03, dt_stable: b.dt_stable_explicit() };
        assert!(check_dofs(&b, "displacement", &[1.0, 2.0], at).is_ok());
        let f = check_dofs(&b, "velocity", &[1.0, f64::NAN], at).unwrap_err();
        assert_eq!(f.code, failure_code::SOLVER);
        let m = &f.message;
        assert!(m.starts_with("the rigid body's velocity of DOF \"rz\" is NaN at t = 3e-1"), "{m}");
        assert!(m.contains("coupling step 9"), "{m}");
        assert!(m.contains("above the stable step 2e-2 s") && m.contains("2/ω_max"), "{m}");
        let stable = At { dt: 0.01, ..at };
        let m = check_dofs(&b, "displacement", &[f64::INFINITY, 0.0], stable).unwrap_err().message;
        assert!(m.contains("DOF \"x\" is inf") && !m.contains("stable step"), "{m}");
    }

    #[test]
    fn names_the_wet_node_of_a_bad_load() {
        let at = At { t: 1.0, step: 99, dt: 0.01, dt_stable: 1.0 };
        let mut loads = vec![NodeLoad { f: [1.0, 2.0, 3.0] }; 4];
        assert!(check_loads(&loads, at).is_ok());
        loads[2].f[1] = f64::NEG_INFINITY;
        let m = check_loads(&loads, at).unwrap_err().message;
        assert!(
            m.contains("-inf (component y) on wet node 2 at t = 1e0 (coupling step 99)"),
            "{m}"
        );
    }

    #[test]
    fn short_numbers_drop_rounding_noise() {
        assert_eq!(short(2.999999999999936e-2), "3e-2");
        assert_eq!(short(1.0979999999999999e1), "1.098e1");
        assert_eq!(short(-0.25), "-2.5e-1");
        assert_eq!(short(f64::INFINITY), "inf");
    }
}
