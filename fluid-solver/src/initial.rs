//! Initial conditions: a background state, then regions (half-space, box, sphere, cylinder)
//! applied in order, each node taking the state of the last region containing it. Every state
//! must be one its EOS admits and every region must hold a node.

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

    /// The conserved state of every node. An error gives the case key (`fluid.initial.<...>`)
    /// and what is wrong of the first state outside the EOS ([`Eos::check_input`]) or the first
    /// region that holds no node of the mesh (it would silently do nothing).
    pub fn state(&self, mesh: &Mesh, eos: &Eos) -> Result<State, (String, String)> {
        for (k, w) in
            std::iter::once(&self.background).chain(self.regions.iter().map(|r| &r.1)).enumerate()
        {
            eos.check_input(w).map_err(|e| {
                let which =
                    if k == 0 { "state".to_string() } else { format!("regions[{}].state", k - 1) };
                (
                    format!("fluid.initial.{which}"),
                    format!("{w:?} is not a valid state of the EOS: {e}"),
                )
            })?;
        }
        for (k, (region, _)) in self.regions.iter().enumerate() {
            if !mesh.coords.iter().any(|&x| region.contains(x)) {
                let (lo, hi) = mesh.bounding_box();
                return Err((
                    format!("fluid.initial.regions[{k}]"),
                    format!(
                        "{} holds no mesh node (the mesh spans {lo:?} to {hi:?})",
                        describe(region)
                    ),
                ));
            }
        }
        Ok(State { cons: mesh.coords.iter().map(|&x| eos.prim_to_cons(&self.at(x))).collect() })
    }
}

/// A region in words, with its parameters.
pub fn describe(region: &Region) -> String {
    match *region {
        Region::HalfSpace { point, normal } => {
            format!("the half space through {point:?} with normal {normal:?}")
        }
        Region::Box { lo, hi } => format!("the box from {lo:?} to {hi:?}"),
        Region::Sphere { center, radius } => {
            format!("the sphere of radius {radius} around {center:?}")
        }
        Region::Cylinder { start, end, radius } => {
            format!("the cylinder of radius {radius} from {start:?} to {end:?}")
        }
    }
}
