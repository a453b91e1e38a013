//! The first-NaN stop: find the first non-finite value of a field and say where it is, so a
//! diverging run stops at once with the field, the node or element, the time and the value (the
//! caller keeps its last good checkpoint).
//!
//! ```
//! use interface_protocol::io::finite::{check_finite, Entity};
//! let v = [[0.0, 1.0, 0.0], [0.0, f64::NAN, 0.0]];
//! let err = check_finite("velocity", Entity::Node, 0.25, &v[..]).unwrap_err();
//! assert_eq!((err.index, err.component), (1, Some(1)));
//! ```

use std::fmt;

/// Where a non-finite value sits in a slice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NonFinite {
    /// Entry (node, element, ...) index.
    pub index: usize,
    /// Component within the entry, `None` for scalar fields.
    pub component: Option<usize>,
    /// The offending value (NaN, +inf or -inf).
    pub value: f64,
}

/// Slices of values that can be scanned for the first non-finite entry.
pub trait FiniteScan {
    /// The first NaN or infinity, in storage order.
    fn first_non_finite(&self) -> Option<NonFinite>;
}

impl FiniteScan for [f64] {
    fn first_non_finite(&self) -> Option<NonFinite> {
        let index = self.iter().position(|v| !v.is_finite())?;
        Some(NonFinite { index, component: None, value: self[index] })
    }
}

impl<const N: usize> FiniteScan for [[f64; N]] {
    fn first_non_finite(&self) -> Option<NonFinite> {
        let flat = self.as_flattened();
        let k = flat.iter().position(|v| !v.is_finite())?;
        Some(NonFinite { index: k / N, component: Some(k % N), value: flat[k] })
    }
}

/// What a field's entries are attached to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Entity {
    Node,
    Element,
    Cell,
    /// A degree of freedom of an assembled vector.
    Dof,
}

impl fmt::Display for Entity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Entity::Node => "node",
            Entity::Element => "element",
            Entity::Cell => "cell",
            Entity::Dof => "dof",
        })
    }
}

/// A field went non-finite: which field, which node/element (and component), when, and the value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "non-finite value {value} in field `{field}`{} at {entity} {index}, t = {time:e}",
    component_text(*.component)
)]
pub struct NonFiniteError {
    pub field: String,
    pub entity: Entity,
    pub index: usize,
    pub component: Option<usize>,
    pub time: f64,
    pub value: f64,
}

fn component_text(c: Option<usize>) -> String {
    c.map(|c| format!(" component {c}")).unwrap_or_default()
}

/// `Ok` if every value of `values` is finite, otherwise the error naming the first bad one.
pub fn check_finite<S: FiniteScan + ?Sized>(
    field: &str,
    entity: Entity,
    time: f64,
    values: &S,
) -> Result<(), NonFiniteError> {
    match values.first_non_finite() {
        None => Ok(()),
        Some(NonFinite { index, component, value }) => {
            Err(NonFiniteError { field: field.to_string(), entity, index, component, time, value })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_first_bad_scalar() {
        let mut v = vec![1.0; 100];
        assert_eq!(v.first_non_finite(), None);
        v[73] = f64::INFINITY;
        v[90] = f64::NAN;
        assert_eq!(
            v.first_non_finite(),
            Some(NonFinite { index: 73, component: None, value: f64::INFINITY })
        );
        assert_eq!(v[..73].first_non_finite(), None);
    }

    #[test]
    fn finds_node_and_component_of_vectors() {
        let mut v = vec![[0.5; 3]; 10];
        v[6][2] = f64::NEG_INFINITY;
        v[7][0] = f64::NAN;
        let nf = v.first_non_finite().unwrap();
        assert_eq!((nf.index, nf.component, nf.value), (6, Some(2), f64::NEG_INFINITY));
        let w = [[1.0, 2.0, 3.0, 4.0, f64::NAN]; 2];
        assert_eq!(w.first_non_finite().map(|n| (n.index, n.component)), Some((0, Some(4))));
        let empty: [[f64; 3]; 0] = [];
        assert_eq!(empty.first_non_finite(), None);
    }

    #[test]
    fn error_message_names_field_entity_time_and_value() {
        let mut rho = vec![1.2; 50];
        assert!(check_finite("rho", Entity::Node, 0.0, &rho[..]).is_ok());
        rho[41] = f64::NAN;
        let err = check_finite("rho", Entity::Node, 1.5e-3, &rho[..]).unwrap_err();
        assert_eq!(err.to_string(), "non-finite value NaN in field `rho` at node 41, t = 1.5e-3");
        let mut s = [[0.0; 6]; 4];
        s[3][5] = f64::INFINITY;
        let err = check_finite("stress", Entity::Element, 2.0, &s[..]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "non-finite value inf in field `stress` component 5 at element 3, t = 2e0"
        );
    }
}
