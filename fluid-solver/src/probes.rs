//! Probes and lines: the fluid state sampled at points (`probes.csv`) and along straight lines
//! (`lines/<name>.csv`). A sample takes the state of the node nearest to the point (exact at
//! nodes; interpolation inside cells is not done). With an embedded surface it takes the nearest
//! node that is active and on the point's side of the surface ([`crate::embedded::sample`]), and
//! a point with none (inside a body) gets `NaN` values and the material [`NO_FLUID`]. [`place`]
//! puts a case's probes and lines on the mesh and refuses any point outside it.

use crate::embedded::sample::sample_node;
use crate::embedded::tracker::Tracker;
use crate::mesh::geometry::{add, dot, norm, scale, sub};
use crate::mesh::{locate, Mesh};
use crate::state::MaterialId;
use crate::time::reached;
use interface_protocol::case::{FluidLine, FluidProbe};
use interface_protocol::io::probes::LinePoint;

/// The `material` of a line sample that has no fluid node to read (inside a body).
pub const NO_FLUID: u32 = u32::MAX;

/// The node a sample at `x` whose nearest node is `nearest` reads: that node without a surface,
/// [`sample_node`] with one (`None`: no fluid there).
pub fn sampled_node(
    mesh: &Mesh,
    surface: Option<&Tracker>,
    x: [f64; 3],
    nearest: usize,
) -> Option<usize> {
    match surface {
        None => Some(nearest),
        Some(tracker) => sample_node(mesh, tracker, x, nearest),
    }
}

/// The primitive state a sample at `x` reads ([`sampled_node`]), `NaN` where there is no fluid.
pub fn sampled_state(
    mesh: &Mesh,
    surface: Option<&Tracker>,
    prim: &[[f64; 5]],
    x: [f64; 3],
    nearest: usize,
) -> [f64; 5] {
    sampled_node(mesh, surface, x, nearest).map_or([f64::NAN; 5], |i| prim[i])
}

/// A case's probes and lines on the mesh.
#[derive(Debug, Clone)]
pub struct Placed {
    /// The node of each probe (nearest to it).
    pub probe_nodes: Vec<usize>,
    /// Where each probe is.
    pub probe_points: Vec<[f64; 3]>,
    pub lines: Vec<Line>,
}

/// Places `probes` (`fluid.probes`) and `lines` (`fluid.lines`) on `mesh`. Every probe and every
/// sample point of a line must lie in a cell of the mesh; an error names the first that does
/// not by its key (`fluid.probes[2].at`, `fluid.lines[0].to`, or the sample point of a line).
pub fn place(
    mesh: &Mesh,
    probes: &[FluidProbe],
    asked: &[FluidLine],
) -> Result<Placed, (String, String)> {
    let lines: Vec<Line> =
        asked.iter().map(|l| Line::new(mesh, &l.name, l.from, l.to, l.points, &l.times)).collect();
    let points: Vec<[f64; 3]> = probes
        .iter()
        .map(|p| p.at)
        .chain(lines.iter().flat_map(|l| l.points.iter().copied()))
        .collect();
    let inside = locate::inside(mesh, &points);
    let outside = |field: String, what: String, x: [f64; 3]| {
        let (lo, hi) = mesh.bounding_box();
        Err((
            field,
            format!(
                "{what}{x:?} lies outside the fluid mesh (in none of its cells; its bounding box \
                 is {lo:?} to {hi:?})"
            ),
        ))
    };
    for (k, p) in probes.iter().enumerate() {
        if !inside[k] {
            return outside(format!("fluid.probes[{k}].at"), String::new(), p.at);
        }
    }
    let mut first = probes.len();
    for (k, line) in lines.iter().enumerate() {
        let n = line.points.len();
        // The ends first: when one is outside, it is the one to name.
        if let Some(j) = [0, n - 1].into_iter().chain(1..n - 1).find(|&j| !inside[first + j]) {
            return match j {
                0 => outside(format!("fluid.lines[{k}].from"), String::new(), asked[k].from),
                j if j == n - 1 => {
                    outside(format!("fluid.lines[{k}].to"), String::new(), asked[k].to)
                }
                j => outside(
                    format!("fluid.lines[{k}]"),
                    format!("sample point {j} of {n} of line `{}`, at ", line.name),
                    line.points[j],
                ),
            };
        }
        first += n;
    }
    let probe_nodes = probes.iter().map(|p| nearest_node(mesh, p.at)).collect();
    let probe_points = probes.iter().map(|p| p.at).collect();
    Ok(Placed { probe_nodes, probe_points, lines })
}

/// The node nearest to `x`.
pub fn nearest_node(mesh: &Mesh, x: [f64; 3]) -> usize {
    let mut best = (f64::INFINITY, 0);
    for (i, c) in mesh.coords.iter().enumerate() {
        let d = sub(*c, x);
        let d2 = dot(d, d);
        if d2 < best.0 {
            best = (d2, i);
        }
    }
    best.1
}

/// A line of `n` equally spaced points from `from` to `to`, each with its nearest node.
#[derive(Debug, Clone)]
pub struct Line {
    pub name: String,
    pub points: Vec<[f64; 3]>,
    pub nodes: Vec<usize>,
    /// Times still to write, ascending (the run lands a step on each).
    pub pending: Vec<f64>,
}

impl Line {
    pub fn new(
        mesh: &Mesh,
        name: &str,
        from: [f64; 3],
        to: [f64; 3],
        n: usize,
        times: &[f64],
    ) -> Line {
        let points: Vec<[f64; 3]> =
            (0..n).map(|k| add(from, scale(sub(to, from), k as f64 / (n - 1) as f64))).collect();
        let nodes = points.iter().map(|&x| nearest_node(mesh, x)).collect();
        let mut pending = times.to_vec();
        pending.sort_by(f64::total_cmp);
        Line { name: name.to_string(), points, nodes, pending }
    }

    /// Whether the next time to write is reached at `t`.
    pub fn due(&self, t: f64) -> bool {
        self.pending.first().is_some_and(|&lt| reached(t, lt))
    }

    /// The samples of the current state: primitive variables, material id (`material` column,
    /// the fluid's id in the EOS table) and level set (`phi`: NaN when `phi` is empty, a run
    /// without a level set) of each point's node ([`sampled_node`] with the embedded surface
    /// `surface`, if any: `NaN` values and material [`NO_FLUID`] where there is no fluid).
    pub fn sample(
        &self,
        mesh: &Mesh,
        surface: Option<&Tracker>,
        prim: &[[f64; 5]],
        material: &[MaterialId],
        phi: &[f64],
    ) -> Vec<LinePoint> {
        let from = self.points[0];
        self.points
            .iter()
            .zip(&self.nodes)
            .map(|(&x, &nearest)| {
                let s = norm(sub(x, from));
                let Some(i) = sampled_node(mesh, surface, x, nearest) else {
                    let nan = f64::NAN;
                    let (v, material) = ([nan; 3], NO_FLUID);
                    return LinePoint { x, s, rho: nan, v, p: nan, material, phi: nan };
                };
                let w = prim[i];
                LinePoint {
                    x,
                    s,
                    rho: w[0],
                    v: [w[1], w[2], w[3]],
                    p: w[4],
                    material: u32::from(material[i]),
                    phi: phi.get(i).copied().unwrap_or(f64::NAN),
                }
            })
            .collect()
    }
}
