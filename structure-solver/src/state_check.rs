//! The finite check of the structure's state, made every step before anything is written (a
//! fold over the arrays, cheap beside the step): the first NaN or infinity of displacement,
//! velocity, acceleration, internal force or a received load stops the step, naming the field,
//! the node (the user's id) and the dof. Runs alone and coupled use this one check.

use interface_protocol::io::finite::FiniteScan;

use crate::model::Model;

/// The names of the six nodal dofs.
pub const DOF_NAMES: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];

/// The first non-finite value of a nodal field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("non-finite value {value} in field `{field}` at node {node} dof {dof}")]
pub struct NonFiniteDof {
    pub field: &'static str,
    /// The user's id of the node.
    pub node: u64,
    pub dof: &'static str,
    pub value: f64,
}

/// `Ok` when every value of `values` (6 per node, `[ux, uy, uz, rx, ry, rz]`) is finite; else
/// the first bad one, its node named by `id` (index -> user id).
pub fn check_dofs(
    field: &'static str,
    values: &[f64],
    id: &dyn Fn(usize) -> u64,
) -> Result<(), NonFiniteDof> {
    match values.first_non_finite() {
        None => Ok(()),
        Some(bad) => Err(NonFiniteDof {
            field,
            node: id(bad.index / 6),
            dof: DOF_NAMES[bad.index % 6],
            value: bad.value,
        }),
    }
}

/// The state of a step: the model's displacement (into `disp`, one per node), the velocity and
/// acceleration per dof, and the internal force per dof when the integrator keeps it.
pub fn check_state(
    model: &dyn Model,
    disp: &mut [[f64; 3]],
    (v, a, f_int): (&[f64], &[f64], Option<&[f64]>),
    id: &dyn Fn(usize) -> u64,
) -> Result<(), NonFiniteDof> {
    model.displacement(disp);
    if let Some(bad) = disp.first_non_finite() {
        return Err(NonFiniteDof {
            field: "displacement",
            node: id(bad.index),
            dof: DOF_NAMES[bad.component.unwrap_or(0)],
            value: bad.value,
        });
    }
    check_dofs("velocity", v, id)?;
    check_dofs("acceleration", a, id)?;
    match f_int {
        Some(f) => check_dofs("internal force", f, id),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_the_field_node_and_dof() {
        let mut v = vec![0.0; 18];
        let ids = |i: usize| [10, 20, 30][i];
        assert!(check_dofs("velocity", &v, &ids).is_ok());
        v[13] = f64::NAN;
        v[17] = f64::INFINITY;
        let e = check_dofs("velocity", &v, &ids).unwrap_err();
        assert_eq!((e.node, e.dof), (30, "uy"));
        assert_eq!(e.to_string(), "non-finite value NaN in field `velocity` at node 30 dof uy");
    }
}
