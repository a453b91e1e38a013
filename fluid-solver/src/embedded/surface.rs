//! The embedded surface as the fluid holds it (DESIGN §5.1): triangles (quads split in two, with
//! the map back to the structure's elements), the crack level set `phi` at the corners of each
//! triangle (thesis §4.3), and the nodal positions and velocities at both ends of the step.
//!
//! Inside a step `[t_a, t_b]` the surface moves on the cubic Hermite path between `(x_a, v_a)` and
//! `(x_b, v_b)` (DESIGN §4): the wall velocity at any stage time is the exact time derivative of
//! the wall position, so a rigid translation moves no mass through the surface.

use crate::mesh::geometry::{cross, dot, sub};
use interface_protocol::messages::SurfaceElement;

/// The surface of one step.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// Node triples into the nodal arrays; quads `(a, b, c, d)` become `(a, b, c)` and `(a, c, d)`.
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the structure element (index into the topology message) it comes from.
    pub element_of: Vec<u32>,
    /// Crack level set at the three corners of each triangle; an intersection counts only where the
    /// interpolated value is `>= 0`. Uncracked elements carry `1.0`.
    pub phi: Vec<[f64; 3]>,
    /// Topology version the triangles were built from.
    pub topology_version: u64,
    /// The surface's edges, each with the triangle sides that hold it; built with the topology.
    pub edges: SurfaceEdges,
    /// Per triangle, its connected part (triangles joined through shared edges, named by one of
    /// them) if that part is open (has an edge a single triangle holds), else `None`; built with
    /// the topology ([`SurfaceEdges::open_parts`]).
    pub open_part: Vec<Option<u32>>,
    /// Start and end of the step.
    pub t_a: f64,
    pub t_b: f64,
    /// Nodal positions and velocities at `t_a` and at `t_b`.
    pub x_a: Vec<[f64; 3]>,
    pub v_a: Vec<[f64; 3]>,
    pub x_b: Vec<[f64; 3]>,
    pub v_b: Vec<[f64; 3]>,
}

/// A surface input that cannot be used, named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SurfaceError {
    #[error("surface element {element} has {n} nodes; triangles (3) and quads (4) are accepted")]
    NodeCount { element: usize, n: u8 },
    #[error(
        "surface element {element} refers to node {node}, but the surface has {n_nodes} nodes"
    )]
    BadNode { element: usize, node: u32, n_nodes: usize },
    #[error("surface element {element} has a non-finite phi {phi:?}")]
    BadPhi { element: usize, phi: [f64; 4] },
    #[error("surface node {node} has a non-finite {what} {value:?}")]
    NonFinite { node: usize, what: &'static str, value: [f64; 3] },
    #[error(
        "surface element {element} (its triangle {corners:?}) is degenerate: area {area:e} m² \
         for a longest edge of {edge:e} m"
    )]
    Degenerate { element: u32, corners: [u32; 3], area: f64, edge: f64 },
    #[error("{got} nodal states for a surface of {expected} nodes")]
    Count { expected: usize, got: usize },
}

/// A triangle whose area is below this fraction of its longest edge squared has no usable normal.
pub const DEGENERATE_AREA: f64 = 1e-12;

/// The triangles of `elements` over `n_nodes` nodes: quads split, the map back, phi per corner.
type Triangulation = (Vec<[u32; 3]>, Vec<u32>, Vec<[f64; 3]>);

impl Surface {
    /// A surface at rest at `x` (positions at both ends equal, velocities zero) from elements, for
    /// a topology `version`; `set_motion` then gives it its motion over a step.
    pub fn new(
        elements: &[SurfaceElement],
        x: Vec<[f64; 3]>,
        version: u64,
    ) -> Result<Surface, SurfaceError> {
        let n_nodes = x.len();
        let (triangles, element_of, phi) = triangulate(elements, n_nodes)?;
        let zero = vec![[0.0; 3]; n_nodes];
        let edges = SurfaceEdges::new(&triangles);
        Ok(Surface {
            open_part: edges.open_parts(triangles.len()),
            edges,
            triangles,
            element_of,
            phi,
            topology_version: version,
            t_a: 0.0,
            t_b: 0.0,
            x_a: x.clone(),
            v_a: zero.clone(),
            x_b: x,
            v_b: zero,
        })
    }

    /// A new topology `version` (after a crack): the triangles of `elements` over the nodes there
    /// are now. The nodal states are kept; nodes the new topology adds are appended first with
    /// [`Surface::append_nodes`].
    pub fn set_topology(
        &mut self,
        elements: &[SurfaceElement],
        version: u64,
    ) -> Result<(), SurfaceError> {
        (self.triangles, self.element_of, self.phi) = triangulate(elements, self.n_nodes())?;
        self.edges = SurfaceEdges::new(&self.triangles);
        self.open_part = self.edges.open_parts(self.triangles.len());
        self.topology_version = version;
        Ok(())
    }

    /// Appends nodes at rest at `x` with velocity `v` at both ends of the step (the phantom nodes
    /// of a crack start where the structure first publishes them).
    pub fn append_nodes(&mut self, x: &[[f64; 3]], v: &[[f64; 3]]) {
        self.x_a.extend_from_slice(x);
        self.x_b.extend_from_slice(x);
        self.v_a.extend_from_slice(v);
        self.v_b.extend_from_slice(v);
    }

    /// Checks nodal states `(x, v)` for this surface before it moves there: one per node, finite,
    /// and no triangle degenerate at `x` (area below [`DEGENERATE_AREA`] of its longest edge
    /// squared), each failure naming the node or the structure element.
    pub fn check_states(&self, x: &[[f64; 3]], v: &[[f64; 3]]) -> Result<(), SurfaceError> {
        let n = self.n_nodes();
        if x.len() != n || v.len() != n {
            return Err(SurfaceError::Count { expected: n, got: x.len().min(v.len()) });
        }
        for (what, values) in [("position", x), ("velocity", v)] {
            if let Some(node) = values.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
                return Err(SurfaceError::NonFinite { node, what, value: values[node] });
            }
        }
        for (t, corners) in self.triangles.iter().enumerate() {
            let [a, b, c] = corners.map(|k| x[k as usize]);
            let (ab, ac, bc) = (sub(b, a), sub(c, a), sub(c, b));
            let edge = [ab, ac, bc].map(|e| dot(e, e)).into_iter().fold(0.0, f64::max);
            let n = cross(ab, ac);
            let twice_area = dot(n, n).sqrt();
            if twice_area.is_nan() || twice_area <= 2.0 * DEGENERATE_AREA * edge {
                return Err(SurfaceError::Degenerate {
                    element: self.element_of[t],
                    corners: *corners,
                    area: 0.5 * twice_area,
                    edge: edge.sqrt(),
                });
            }
        }
        Ok(())
    }

    /// Number of surface nodes.
    pub fn n_nodes(&self) -> usize {
        self.x_a.len()
    }

    /// Starts a new step `[t_a, t_b]`: the old end state becomes the start state, and
    /// `(x_b, v_b)` the new end state.
    pub fn advance(&mut self, t_b: f64, x_b: &[[f64; 3]], v_b: &[[f64; 3]]) {
        std::mem::swap(&mut self.x_a, &mut self.x_b);
        std::mem::swap(&mut self.v_a, &mut self.v_b);
        self.x_b.copy_from_slice(x_b);
        self.v_b.copy_from_slice(v_b);
        self.t_a = self.t_b;
        self.t_b = t_b;
    }

    /// Position and velocity of node `n` at time `t` on the cubic Hermite path (DESIGN §4); at
    /// `t_a` and `t_b` exactly the end states. A step of zero length returns the end state.
    #[inline]
    pub fn node_at(&self, n: usize, t: f64) -> ([f64; 3], [f64; 3]) {
        let path = HermitePath { t_a: self.t_a, t_b: self.t_b };
        path.at(t, self.x_a[n], self.v_a[n], self.x_b[n], self.v_b[n])
    }

    /// Corners and corner velocities of triangle `tri` at time `t`.
    #[inline]
    pub fn triangle_at(&self, tri: usize, t: f64) -> ([[f64; 3]; 3], [[f64; 3]; 3]) {
        let c = self.triangles[tri];
        let p = c.map(|n| self.node_at(n as usize, t));
        (p.map(|q| q.0), p.map(|q| q.1))
    }

    /// Position and velocity of the point with barycentric coordinates `bary` in triangle `tri` at
    /// time `t` (the wall velocity the fluid-structure Riemann problem of Alg. 5.1 sees).
    #[inline]
    pub fn point_at(&self, tri: usize, bary: [f64; 3], t: f64) -> ([f64; 3], [f64; 3]) {
        let (x, v) = self.triangle_at(tri, t);
        let mut px = [0.0; 3];
        let mut pv = [0.0; 3];
        for m in 0..3 {
            for k in 0..3 {
                px[k] += bary[m] * x[m][k];
                pv[k] += bary[m] * v[m][k];
            }
        }
        (px, pv)
    }
}

/// The edges of a triangulated surface: each distinct node pair with the triangle sides holding
/// it, `(triangle, k)` for the side opposite corner `k`; one on a free edge, two on a manifold
/// edge, more where sheets meet. With them, the triangles around each node.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceEdges {
    /// Edge `m` is held by `sides[offsets[m]..offsets[m + 1]]`.
    offsets: Vec<u32>,
    sides: Vec<(u32, u8)>,
    /// Per triangle, the edge of each side.
    edge_of: Vec<[u32; 3]>,
    /// The triangles holding node `v` are `around[around_offsets[v]..around_offsets[v + 1]]`,
    /// ascending, each once.
    around_offsets: Vec<u32>,
    around: Vec<u32>,
}

impl SurfaceEdges {
    /// The edges of `triangles`, by sorting their sides by node pair.
    pub fn new(triangles: &[[u32; 3]]) -> SurfaceEdges {
        let mut keys: Vec<([u32; 2], u32, u8)> = Vec::with_capacity(3 * triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3u8 {
                let (a, b) = (tri[(k as usize + 1) % 3], tri[(k as usize + 2) % 3]);
                keys.push(([a.min(b), a.max(b)], t as u32, k));
            }
        }
        keys.sort_unstable();
        let mut offsets = vec![0];
        let mut edge_of = vec![[0; 3]; triangles.len()];
        for (m, run) in keys.chunk_by(|x, y| x.0 == y.0).enumerate() {
            offsets.push(offsets.last().copied().unwrap_or(0) + run.len() as u32);
            for &(_, t, k) in run {
                edge_of[t as usize][k as usize] = m as u32;
            }
        }
        let sides = keys.into_iter().map(|(_, t, k)| (t, k)).collect();
        // The triangles around each node by counting, in triangle order.
        let corners = |tri: &[u32; 3]| {
            let tri = *tri;
            (0..3).filter(move |&k| !tri[..k].contains(&tri[k])).map(move |k| tri[k])
        };
        let n_nodes = triangles.iter().flatten().max().map_or(0, |&v| v as usize + 1);
        let mut around_offsets = vec![0u32; n_nodes + 1];
        for v in triangles.iter().flat_map(corners) {
            around_offsets[v as usize + 1] += 1;
        }
        for v in 0..n_nodes {
            around_offsets[v + 1] += around_offsets[v];
        }
        let mut next = around_offsets.clone();
        let mut around = vec![0; around_offsets[n_nodes] as usize];
        for (t, tri) in triangles.iter().enumerate() {
            for v in corners(tri) {
                around[next[v as usize] as usize] = t as u32;
                next[v as usize] += 1;
            }
        }
        SurfaceEdges { offsets, sides, edge_of, around_offsets, around }
    }

    /// Each edge's triangle sides.
    pub fn runs(&self) -> impl Iterator<Item = &[(u32, u8)]> {
        self.offsets.windows(2).map(|w| &self.sides[w[0] as usize..w[1] as usize])
    }

    /// The number of the edge side `k` of triangle `t` lies on (the edges in the order of
    /// [`SurfaceEdges::runs`]).
    pub fn edge_of(&self, t: u32, k: u8) -> u32 {
        self.edge_of[t as usize][k as usize]
    }

    /// The triangle sides holding edge `m`.
    pub fn run(&self, m: u32) -> &[(u32, u8)] {
        let m = m as usize;
        &self.sides[self.offsets[m] as usize..self.offsets[m + 1] as usize]
    }

    /// The triangles holding node `v`, ascending (none for a node of no triangle).
    pub fn around(&self, v: u32) -> &[u32] {
        let v = v as usize;
        match (self.around_offsets.get(v), self.around_offsets.get(v + 1)) {
            (Some(&a), Some(&b)) => &self.around[a as usize..b as usize],
            _ => &[],
        }
    }

    /// Per triangle (of `n`), its connected part (triangles joined through shared edges, named
    /// by one of them) if that part is open (has an edge a single triangle holds), else `None`:
    /// union-find over the edges.
    pub fn open_parts(&self, n: usize) -> Vec<Option<u32>> {
        let mut parent: Vec<u32> = (0..n as u32).collect();
        let find = |parent: &mut Vec<u32>, mut a: u32| {
            while parent[a as usize] != a {
                parent[a as usize] = parent[parent[a as usize] as usize];
                a = parent[a as usize];
            }
            a
        };
        let mut free = Vec::new();
        for run in self.runs() {
            if run.len() == 1 {
                free.push(run[0].0);
            }
            for w in run.windows(2) {
                let (a, b) = (find(&mut parent, w[0].0), find(&mut parent, w[1].0));
                parent[a as usize] = b;
            }
        }
        let mut open = vec![false; n];
        for t in free {
            let r = find(&mut parent, t);
            open[r as usize] = true;
        }
        (0..n as u32)
            .map(|t| {
                let r = find(&mut parent, t);
                open[r as usize].then_some(r)
            })
            .collect()
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.offsets[..]) + std::mem::size_of_val(&self.sides[..])
    }
}

/// Splits `elements` into triangles over `n_nodes` nodes, checking node counts, indices and phi.
fn triangulate(elements: &[SurfaceElement], n_nodes: usize) -> Result<Triangulation, SurfaceError> {
    let mut triangles = Vec::with_capacity(elements.len() * 2);
    let mut element_of = Vec::with_capacity(elements.len() * 2);
    let mut phi = Vec::with_capacity(elements.len() * 2);
    for (k, e) in elements.iter().enumerate() {
        let n = e.n_nodes as usize;
        if n != 3 && n != 4 {
            return Err(SurfaceError::NodeCount { element: k, n: e.n_nodes });
        }
        if let Some(&node) = e.nodes[..n].iter().find(|&&v| v as usize >= n_nodes) {
            return Err(SurfaceError::BadNode { element: k, node, n_nodes });
        }
        if e.phi[..n].iter().any(|p| !p.is_finite()) {
            return Err(SurfaceError::BadPhi { element: k, phi: e.phi });
        }
        let corners: &[[usize; 3]] = if n == 3 { &[[0, 1, 2]] } else { &[[0, 1, 2], [0, 2, 3]] };
        for c in corners {
            triangles.push(c.map(|m| e.nodes[m]));
            element_of.push(k as u32);
            phi.push(c.map(|m| e.phi[m]));
        }
    }
    Ok((triangles, element_of, phi))
}

/// The cubic Hermite path over `[t_a, t_b]` (DESIGN §4): the cubic through `(x_a, v_a)` at `t_a`
/// and `(x_b, v_b)` at `t_b`, its velocity the exact derivative of its position. The surface's
/// path inside a fluid step, and the path of the structure's kinematics inside a coupling step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HermitePath {
    pub t_a: f64,
    pub t_b: f64,
}

impl HermitePath {
    /// Position and velocity at `t` (clamped to `[t_a, t_b]`): exactly the end states at `t_a` and
    /// `t_b`; the end state on a path of zero length.
    #[inline]
    pub fn at(
        &self,
        t: f64,
        xa: [f64; 3],
        va: [f64; 3],
        xb: [f64; 3],
        vb: [f64; 3],
    ) -> ([f64; 3], [f64; 3]) {
        let h = self.t_b - self.t_a;
        if h <= 0.0 {
            return (xb, vb);
        }
        let s = ((t - self.t_a) / h).clamp(0.0, 1.0);
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) =
            (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, 3.0 * s2 - 2.0 * s3, s3 - s2);
        let (d00, d10, d01, d11) =
            (6.0 * (s2 - s), 3.0 * s2 - 4.0 * s + 1.0, 6.0 * (s - s2), 3.0 * s2 - 2.0 * s);
        let mut x = [0.0; 3];
        let mut v = [0.0; 3];
        for k in 0..3 {
            x[k] = h00 * xa[k] + h10 * h * va[k] + h01 * xb[k] + h11 * h * vb[k];
            v[k] = (d00 * xa[k] + d01 * xb[k]) / h + d10 * va[k] + d11 * vb[k];
        }
        (x, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Surface {
        let e = SurfaceElement { nodes: [0, 1, 2, 3], n_nodes: 4, ..Default::default() };
        let x = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        Surface::new(&[e], x, 1).unwrap()
    }

    #[test]
    fn quads_split_into_two_triangles_with_the_map_back() {
        let s = quad();
        assert_eq!(s.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(s.element_of, vec![0, 0]);
    }

    #[test]
    fn bad_elements_are_named() {
        let e = SurfaceElement { nodes: [0, 1, 9, 0], n_nodes: 3, ..Default::default() };
        let err = Surface::new(&[e], vec![[0.0; 3]; 3], 0).unwrap_err();
        assert_eq!(err, SurfaceError::BadNode { element: 0, node: 9, n_nodes: 3 });
        let e = SurfaceElement { n_nodes: 5, ..Default::default() };
        assert!(matches!(
            Surface::new(&[e], vec![[0.0; 3]; 3], 0),
            Err(SurfaceError::NodeCount { .. })
        ));
    }

    /// States that cannot be tracked are named: a non-finite position or velocity by node, a
    /// triangle collapsed to a line by its structure element, a wrong count; a new topology over
    /// appended nodes replaces the triangles and keeps the states.
    #[test]
    fn bad_states_and_new_topologies() {
        let mut s = quad();
        let (x, v) = (s.x_b.clone(), vec![[0.0; 3]; 4]);
        assert_eq!(s.check_states(&x, &v), Ok(()));
        let mut bad = x.clone();
        bad[3][2] = f64::INFINITY;
        assert_eq!(
            s.check_states(&bad, &v),
            Err(SurfaceError::NonFinite { node: 3, what: "position", value: bad[3] })
        );
        let mut w = v.clone();
        w[1][0] = f64::NAN;
        assert!(matches!(
            s.check_states(&x, &w),
            Err(SurfaceError::NonFinite { node: 1, what: "velocity", .. })
        ));
        // Node 3 on the diagonal 0-2: the second triangle (0, 2, 3) has no area.
        let mut flat = x.clone();
        flat[3] = [0.5, 0.5, 0.0];
        assert!(matches!(
            s.check_states(&flat, &v),
            Err(SurfaceError::Degenerate { element: 0, corners: [0, 2, 3], .. })
        ));
        assert_eq!(
            s.check_states(&x[..3], &v[..3]),
            Err(SurfaceError::Count { expected: 4, got: 3 })
        );
        s.append_nodes(&[[2.0, 0.0, 0.0]], &[[0.0, 1.0, 0.0]]);
        let tri =
            SurfaceElement { nodes: [1, 4, 2, 0], n_nodes: 3, phi: [0.5; 4], ..Default::default() };
        s.set_topology(&[tri], 2).unwrap();
        assert_eq!(
            (s.triangles.clone(), s.phi.clone(), s.topology_version),
            (vec![[1, 4, 2]], vec![[0.5; 3]], 2)
        );
        assert_eq!(
            (s.x_a[4], s.x_b[4], s.v_b[4]),
            ([2.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0])
        );
        let far = SurfaceElement { nodes: [1, 5, 2, 0], n_nodes: 3, ..Default::default() };
        assert_eq!(
            s.set_topology(&[far], 3),
            Err(SurfaceError::BadNode { element: 0, node: 5, n_nodes: 5 })
        );
    }

    /// The Hermite path reproduces any cubic motion exactly, and its velocity is the exact
    /// derivative of its position (checked by a central difference).
    #[test]
    fn hermite_path_is_exact_for_cubics_and_consistent() {
        let mut s = quad();
        let x = |t: f64| [1.0 + 2.0 * t - t * t * t, 0.5 * t * t, 3.0];
        let v = |t: f64| [2.0 - 3.0 * t * t, t, 0.0];
        let (ta, tb) = (0.3, 0.8);
        s.t_b = ta;
        let xa = [x(ta); 4];
        let va = [v(ta); 4];
        s.advance(ta, &xa, &va);
        s.advance(tb, &[x(tb); 4], &[v(tb); 4]);
        assert_eq!((s.t_a, s.t_b), (ta, tb));
        for k in 0..=10 {
            let t = ta + (tb - ta) * k as f64 / 10.0;
            let (px, pv) = s.node_at(2, t);
            for c in 0..3 {
                assert!((px[c] - x(t)[c]).abs() < 1e-14, "x at {t}");
                assert!((pv[c] - v(t)[c]).abs() < 1e-13, "v at {t}");
            }
        }
        let (t, h) = (0.55, 1e-6);
        let d = (s.node_at(0, t + h).0[0] - s.node_at(0, t - h).0[0]) / (2.0 * h);
        assert!((d - s.node_at(0, t).1[0]).abs() < 1e-8);
        let (p, w) = s.point_at(1, [0.2, 0.3, 0.5], tb);
        assert!((p[0] - x(tb)[0]).abs() < 1e-14 && (w[0] - v(tb)[0]).abs() < 1e-13);
    }
}
