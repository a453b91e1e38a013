//! What the residual needs from the embedded boundary in one fluid step (DESIGN §5.1): the
//! special edges of every block (the two-material edges of the scheme merged with the cut edges
//! and the uncut edges that touch a node that is not active), the gradient operator with those
//! edges masked out (flow gradients never cross the surface or a material interface), and the
//! wall fluxes of Alg. 5.1 ([`super::riemann_fs`]). Built once per step from the tracker, read by
//! the residual at each stage time.

use super::riemann_fs::{one_sided, End, WallFluxError, WallFluxView, WallMaterial, WallPressures};
use super::tracker::Tracker;
use crate::flux::wall_flux;
use crate::mesh::blocks::Window;
use crate::reconstruct::gradient::LsqGradient;
use crate::riemann::PressureCutoff;
use crate::semidiscretization::{FluidError, Semidiscretization};
use crate::special_edges::{SpecialEdge, SpecialEdges, SpecialKind};
use interface_protocol::case::InterfaceTreatment;

/// The embedded boundary as one step's residuals read it.
#[derive(Debug, Clone)]
pub struct EmbeddedStep {
    /// Two-material, frozen and cut edges, per block.
    pub special: SpecialEdges,
    /// Least-squares gradients through the ordinary edges only.
    pub gradient: LsqGradient,
    /// The wall material of each fluid (EOS and cavitation cut-off).
    pub materials: Vec<WallMaterial>,
    /// Number of uncut edges with exactly one active end (taken as slip walls).
    pub frozen_edges: usize,
    /// The states of the cut-edge fluxes ([`super::riemann_fs::interface`]); the second-order
    /// form needs the scheme's gradients (a first-order scheme takes the first-order form).
    pub interface: InterfaceTreatment,
}

impl EmbeddedStep {
    /// The step's view of `tracker` for the scheme `semi` with the cut-off `p_cut` (Pa; `None`:
    /// the EOS defaults of [`PressureCutoff`]) and the interface treatment `interface`.
    pub fn new(
        semi: &Semidiscretization,
        tracker: &Tracker,
        p_cut: Option<f64>,
        interface: InterfaceTreatment,
    ) -> EmbeddedStep {
        let mesh = &semi.mesh;
        let active = &tracker.active;
        let cut = tracker.cuts.cut_mask(mesh.n_edges());
        let material = semi.material();
        let mut frozen = Vec::new();
        let mut used = vec![true; mesh.n_edges()];
        for (e, &[i, j]) in mesh.edges.iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            let (ai, aj) = (active[i], active[j]);
            if cut[e] || !ai || !aj || material[i] != material[j] {
                used[e] = false;
            }
            if !cut[e] && ai != aj {
                frozen.push(SpecialEdge { edge: e as u32, kind: SpecialKind::Frozen });
            }
        }
        let frozen_edges = frozen.len();
        let cuts: Vec<SpecialEdge> = tracker
            .cuts
            .cuts
            .iter()
            .map(|c| SpecialEdge { edge: c.edge, kind: SpecialKind::Cut })
            .collect();
        let blocks = &mesh.blocks;
        let special = semi
            .special_edges()
            .merge(&SpecialEdges::from_sorted(blocks, frozen), blocks)
            .merge(&SpecialEdges::from_sorted(blocks, cuts), blocks);
        let gradient = LsqGradient::with_planes(mesh, Some(&used), semi.gradient.planes().clone());
        let materials = semi
            .eos
            .iter()
            .map(|eos| WallMaterial {
                eos: *eos,
                cutoff: p_cut.map_or_else(
                    || PressureCutoff::default_for(eos),
                    |p_cut| PressureCutoff { p_cut },
                ),
            })
            .collect();
        let interface = match semi.numerics.second_order() {
            true => interface,
            false => InterfaceTreatment::FirstOrder,
        };
        EmbeddedStep { special, gradient, materials, frozen_edges, interface }
    }
}

/// The embedded boundary at one stage time, as the residual reads it.
#[derive(Clone, Copy)]
pub struct Wall<'a> {
    pub step: &'a EmbeddedStep,
    pub tracker: &'a Tracker,
    /// Stage time (the wall velocity is taken there).
    pub t: f64,
}

/// Nodal gradients of the primitive states, `grad[i][k] = ∇W_k` at node `i`.
pub type Gradients = [[[f64; 3]; 5]];

impl Wall<'_> {
    /// The wall fluxes' view of the states `prim` and their gradients `grad` (read only by the
    /// second-order interface).
    fn view<'b>(
        &'b self,
        semi: &'b Semidiscretization,
        prim: &'b [[f64; 5]],
        grad: &'b Gradients,
    ) -> WallFluxView<'b> {
        let second_order = self.step.interface == InterfaceTreatment::SecondOrder;
        WallFluxView {
            mesh: &semi.mesh,
            surface: &self.tracker.surface,
            t: self.t,
            scheme: semi.numerics.flux,
            active: &self.tracker.active,
            material: semi.material(),
            materials: &self.step.materials,
            prim,
            grad: second_order.then_some(grad),
            limiter: semi.numerics.limiter,
        }
    }

    /// Adds the fluxes of the special edge `s` of kind `Cut` or `Frozen` to the residuals of its
    /// active ends: Alg. 5.1 at a cut edge; a slip wall on the facet at a frozen edge.
    pub fn edge_flux(
        &self,
        semi: &Semidiscretization,
        s: SpecialEdge,
        prim: &[[f64; 5]],
        grad: &Gradients,
        r: &mut Window<'_, [f64; 5]>,
    ) -> Result<(), FluidError> {
        let mesh = &semi.mesh;
        let e = s.edge as usize;
        let [i, j] = mesh.edges[e].map(|v| v as usize);
        let active = &self.tracker.active;
        match s.kind {
            SpecialKind::Cut => {
                let cut = self.tracker.cuts.find(s.edge).expect("a cut special edge is cut");
                let view = self.view(semi, prim, grad);
                for (end, node) in [(End::I, i), (End::J, j)] {
                    if active[node] {
                        let f = one_sided(&view, cut, end).map_err(FluidError::Wall)?;
                        for k in 0..5 {
                            r[node][k] += f.flux[k];
                        }
                    }
                }
            }
            SpecialKind::Frozen => {
                let nu = mesh.edge_normals[e];
                let (node, n) = if active[i] { (i, nu) } else { (j, nu.map(|c| -c)) };
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                let unit = n.map(|c| c / len);
                let f = wall_flux(
                    semi.numerics.flux,
                    semi.eos_at(node),
                    &prim[node],
                    &n,
                    &unit,
                    &[0.0; 3],
                )
                .map_err(|error| FluidError::FrozenEdge {
                    edge: e,
                    node,
                    position: mesh.coords[node],
                    error,
                })?;
                for k in 0..5 {
                    r[node][k] += f.flux[k];
                }
            }
            SpecialKind::TwoMaterial => unreachable!("two-material edges are the scheme's"),
        }
        Ok(())
    }

    /// `p*` on both sides of every cut edge from the states `prim` and their gradients `grad`
    /// through the step's gradient operator (the loads' input, Alg. 5.3 and 5.4), and the number
    /// of cavitation clips.
    pub fn pressures(
        &self,
        semi: &Semidiscretization,
        prim: &[[f64; 5]],
        grad: &Gradients,
    ) -> Result<(Vec<WallPressures>, usize), WallFluxError> {
        let view = self.view(semi, prim, grad);
        let mesh = &semi.mesh;
        let mut clips = 0;
        let mut out = Vec::with_capacity(self.tracker.cuts.cuts.len());
        for cut in &self.tracker.cuts.cuts {
            let [i, j] = mesh.edges[cut.edge as usize].map(|v| v as usize);
            let mut ps = [f64::NAN; 2];
            for (k, (end, node)) in [(End::I, i), (End::J, j)].into_iter().enumerate() {
                if self.tracker.active[node] {
                    let s = one_sided(&view, cut, end)?;
                    ps[k] = s.p;
                    clips += s.clipped as usize;
                }
            }
            out.push(ps);
        }
        Ok((out, clips))
    }
}
