//! Initial conditions: a background state and fluid, then regions (half-space, box, sphere,
//! cylinder) applied in order, each node taking the state and fluid of the last region containing
//! it. Every state must be one its own fluid's EOS admits and every region must hold a node.

use crate::eos::Eos;
use crate::mesh::Mesh;
use crate::state::{MaterialId, State};
use interface_protocol::case::Region;

/// A primitive state and the material (fluid) it belongs to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fill {
    pub state: [f64; 5],
    pub material: MaterialId,
}

/// A background fill and `(region, fill)` pairs, later ones winning.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialCondition {
    pub background: Fill,
    pub regions: Vec<(Region, Fill)>,
}

impl InitialCondition {
    /// A uniform state of material 0.
    pub fn uniform(w: [f64; 5]) -> InitialCondition {
        InitialCondition { background: Fill { state: w, material: 0 }, regions: Vec::new() }
    }

    /// One fluid (material 0): the background state, then `(region, state)` pairs.
    pub fn single(background: [f64; 5], regions: &[(Region, [f64; 5])]) -> InitialCondition {
        InitialCondition {
            background: Fill { state: background, material: 0 },
            regions: regions.iter().map(|&(r, w)| (r, Fill { state: w, material: 0 })).collect(),
        }
    }

    /// The fill at a point.
    pub fn at(&self, x: [f64; 3]) -> Fill {
        self.regions.iter().rev().find(|(r, _)| r.contains(x)).map_or(self.background, |r| r.1)
    }

    /// The conserved state and material id of every node, with the EOS table `eos` (indexed by
    /// material id). An error gives the case key (`fluid.initial.<...>`) and what is wrong of the
    /// first state outside its own fluid's EOS ([`Eos::check_input`]) or the first region that
    /// holds no node of the mesh (it would silently do nothing).
    pub fn state(&self, mesh: &Mesh, eos: &[Eos]) -> Result<State, (String, String)> {
        for (k, fill) in
            std::iter::once(&self.background).chain(self.regions.iter().map(|r| &r.1)).enumerate()
        {
            let which = |leaf: &str| {
                let at = if k == 0 { String::new() } else { format!("regions[{}].", k - 1) };
                format!("fluid.initial.{at}{leaf}")
            };
            let m = fill.material;
            let Some(law) = eos.get(m as usize) else {
                return Err((
                    which("fluid"),
                    format!("material {m} is not in the EOS table of {} fluids", eos.len()),
                ));
            };
            let w = &fill.state;
            law.check_input(w).map_err(|e| {
                let whose = if eos.len() == 1 {
                    "the EOS".to_string()
                } else {
                    format!("its fluid's EOS (material {m}, {law:?})")
                };
                (which("state"), format!("{w:?} is not a valid state of {whose}: {e}"))
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
        let fills: Vec<Fill> = mesh.coords.iter().map(|&x| self.at(x)).collect();
        Ok(State {
            cons: fills.iter().map(|f| eos[f.material as usize].prim_to_cons(&f.state)).collect(),
            material: fills.iter().map(|f| f.material).collect(),
            phi: Vec::new(),
        })
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
