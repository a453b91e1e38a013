//! Initial conditions: a background state, then regions (half-space, box, sphere, cylinder)
//! applied in order, each node taking the state of the last region containing it.

use crate::eos::Eos;
use crate::mesh::Mesh;
use crate::state::State;
use interface_protocol::case::Region;

/// A background primitive state and `(region, primitive state)` pairs, later ones winning.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialCondition {
    pub background: [f64; 5],
    pub regions: Vec<(Region, [f64; 5])>,
}

impl InitialCondition {
    /// A uniform state.
    pub fn uniform(w: [f64; 5]) -> InitialCondition {
        InitialCondition { background: w, regions: Vec::new() }
    }

    /// The primitive state at a point.
    pub fn at(&self, x: [f64; 3]) -> [f64; 5] {
        self.regions.iter().rev().find(|(r, _)| r.contains(x)).map_or(self.background, |r| r.1)
    }

    /// The conserved state of every node; an error names the first state outside the EOS.
    pub fn state(&self, mesh: &Mesh, eos: &Eos) -> Result<State, String> {
        for (k, w) in
            std::iter::once(&self.background).chain(self.regions.iter().map(|r| &r.1)).enumerate()
        {
            eos.check(w).map_err(|e| {
                let which =
                    if k == 0 { "state".to_string() } else { format!("regions[{}].state", k - 1) };
                format!("fluid.initial.{which} = {w:?} is not a valid state of the EOS: {e}")
            })?;
        }
        Ok(State { cons: mesh.coords.iter().map(|&x| eos.prim_to_cons(&self.at(x))).collect() })
    }
}
