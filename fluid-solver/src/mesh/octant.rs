//! The ball-octant mesher: hexes filling the octant `x, y, z >= 0` of a ball, for problems with a
//! centre of symmetry (bubbles, blasts). A uniform cube `[0, a]³` of `n` cells per edge at the
//! centre, then layers of `3 n²` hexes (an O-grid: one block over each of the cube's three outer
//! faces) out to the sphere of radius `R`. The layers keep the cube's spacing `h0 = a/n` out to a
//! distance `fine`, then grow by `grading` each, so a tensor grid's `N³` nodes become
//! `(n + 1)³ + 3 n² m`: the spacing along the radius follows the waves while the spacing across
//! it grows with the radius. Boundaries: the symmetry planes `xmin, ymin, zmin` and the sphere
//! `outer`.
//!
//! Layer `L` (radius `r_L` along the axes, `r_0 = a`) puts the point `a d` of the cube's surface
//! (`|d|_∞ = 1`) at `d/|d| (a |d| (1 - t_L) + R t_L)`, `t_L = (r_L - a)/(R - a)`: linear in the
//! radius between the cube and the sphere, so a layer's thickness varies by `a (√3 - 1)/R`
//! relative across it.

use super::geometry::{cross, dot};
use super::{Cell, CellKind, MeshError, RawMesh, TaggedFace};

/// Names of the boundaries, by patch index.
pub const PATCH_NAMES: [&str; 4] = ["xmin", "ymin", "zmin", "outer"];

/// An octant of the ball of radius `radius` about the origin.
#[derive(Debug, Clone, PartialEq)]
pub struct OctantSpec {
    /// Edge `a` of the uniform core cube `[0, a]³`.
    pub core: f64,
    /// Cells `n` along each edge of the core.
    pub cells: usize,
    /// Distance from the centre, along the axes, out to which the layers keep `h0 = a/n`.
    pub fine: f64,
    /// The outer sphere's radius `R`.
    pub radius: f64,
    /// Ratio of successive layer thicknesses beyond `fine` (> 1).
    pub grading: f64,
    /// Radii (along the axes, ascending) past which the layers' faces have half as many cells
    /// along each side, through a layer of 2:1 transition cells; each halving needs an even
    /// count.
    pub coarsen: Vec<f64>,
}

impl From<&interface_protocol::case::OctantMesh> for OctantSpec {
    /// The mesher's spec from a case's `fluid.mesh.octant` (`fine` defaulting to the core).
    fn from(o: &interface_protocol::case::OctantMesh) -> OctantSpec {
        OctantSpec {
            core: o.core,
            cells: o.cells,
            fine: o.fine.unwrap_or(o.core),
            radius: o.radius,
            grading: o.grading,
            coarsen: o.coarsen.clone(),
        }
    }
}

impl OctantSpec {
    /// The layers' radii along the axes, from `a` to `R`: steps of `h0` out to `fine`, then
    /// `h0 q, h0 q², ...` scaled (down, by less than one step's growth) to end on `R`.
    pub fn layer_radii(&self) -> Vec<f64> {
        let (a, r_out) = (self.core, self.radius);
        let h0 = a / self.cells as f64;
        let fine = ((self.fine.max(a) - a) / h0).round() as usize;
        let mut radii: Vec<f64> = (0..=fine).map(|k| a + k as f64 * h0).collect();
        let start = *radii.last().unwrap();
        if start >= r_out {
            radii.retain(|&r| r < r_out);
            radii.push(r_out);
            return radii;
        }
        let mut steps = Vec::new();
        let (mut h, mut sum) = (h0, 0.0);
        while sum < r_out - start {
            h *= self.grading;
            steps.push(h);
            sum += h;
        }
        let scale = (r_out - start) / sum;
        let mut r = start;
        for (k, s) in steps.iter().enumerate() {
            r += s * scale;
            radii.push(if k + 1 == steps.len() { r_out } else { r });
        }
        radii
    }

    fn check(&self) -> Result<(), MeshError> {
        let bad = |what: String| Err(MeshError::Input(format!("octant mesh: {what}")));
        if self.cells == 0 {
            return bad("the core needs at least one cell".into());
        }
        if !(self.core.is_finite() && self.core > 0.0) {
            return bad(format!("the core's edge must be > 0, got {}", self.core));
        }
        if !(self.radius.is_finite() && self.radius > self.core * 3f64.sqrt()) {
            return bad(format!(
                "the radius must exceed the core's diagonal {} (core {}), got {}",
                self.core * 3f64.sqrt(),
                self.core,
                self.radius
            ));
        }
        if !(self.grading.is_finite() && self.grading > 1.0) {
            return bad(format!("the grading must be > 1, got {}", self.grading));
        }
        if !self.fine.is_finite() {
            return bad(format!("`fine` must be finite, got {}", self.fine));
        }
        let mut m = self.cells;
        for (k, &r) in self.coarsen.iter().enumerate() {
            if m % 2 != 0 {
                return bad(format!(
                    "coarsening {k} (at {r}) halves {m} cells per side: it needs an even count"
                ));
            }
            if !(r.is_finite() && r > self.fine.max(self.core))
                || (k > 0 && r <= self.coarsen[k - 1])
            {
                return bad(format!(
                    "the coarsening radii must ascend beyond `fine` ({}), got {:?}",
                    self.fine, self.coarsen
                ));
            }
            m /= 2;
        }
        Ok(())
    }

    /// The face resolution of each layer: `cells`, halved at the first layer past each radius of
    /// `coarsen`.
    pub fn resolutions(&self, radii: &[f64]) -> Vec<usize> {
        let mut res = vec![self.cells; radii.len()];
        let mut next = 0;
        for l in 1..radii.len() {
            res[l] = res[l - 1];
            if next < self.coarsen.len() && radii[l] > self.coarsen[next] {
                res[l] /= 2;
                next += 1;
            }
        }
        res
    }

    /// The numbers of nodes and cells the mesh will have.
    pub fn size(&self) -> (usize, usize) {
        let radii = self.layer_radii();
        let res = self.resolutions(&radii);
        let mut nodes = (self.cells + 1).pow(3);
        let mut cells = self.cells.pow(3);
        for l in 1..res.len() {
            let m = res[l];
            nodes += 3 * m * m + 3 * m + 1;
            cells += 3 * m * m * if m == res[l - 1] { 1 } else { 9 };
        }
        (nodes, cells)
    }

    /// Builds the raw mesh.
    pub fn raw(&self) -> Result<RawMesh, MeshError> {
        self.check()?;
        let n = self.cells;
        let (a, r_out) = (self.core, self.radius);
        let radii = self.layer_radii();
        let res = self.resolutions(&radii);
        let layers = radii.len() - 1;
        let lattice = |m: usize, p: [usize; 3]| p[0] + (m + 1) * (p[1] + (m + 1) * p[2]);
        // Per resolution, the points of the cube's surface `max = m` and their numbers.
        let mut surfaces: Vec<(usize, Vec<u32>, Vec<[usize; 3]>)> = Vec::new();
        for &m in &res[1..] {
            if surfaces.iter().all(|s| s.0 != m) {
                let mut index = vec![u32::MAX; (m + 1).pow(3)];
                let mut points = Vec::new();
                for k in 0..=m {
                    for j in 0..=m {
                        for i in 0..=m {
                            if i == m || j == m || k == m {
                                index[lattice(m, [i, j, k])] = points.len() as u32;
                                points.push([i, j, k]);
                            }
                        }
                    }
                }
                surfaces.push((m, index, points));
            }
        }
        let surface = |m: usize| surfaces.iter().find(|s| s.0 == m).unwrap();
        let n_core = (n + 1).pow(3);
        // The first node of each layer (layer 0 is the core's surface, in the core's lattice).
        let mut first = vec![0usize; layers + 2];
        first[1] = n_core;
        for l in 1..=layers {
            first[l + 1] = first[l] + surface(res[l]).2.len();
        }
        let id = |l: usize, p: [usize; 3]| -> u32 {
            if l == 0 {
                lattice(n, p) as u32
            } else {
                let m = res[l];
                (first[l] + surface(m).1[lattice(m, p)] as usize) as u32
            }
        };
        let h0 = a / n as f64;
        let mut coords = Vec::with_capacity(first[layers + 1]);
        for k in 0..=n {
            for j in 0..=n {
                for i in 0..=n {
                    coords.push([i as f64 * h0, j as f64 * h0, k as f64 * h0]);
                }
            }
        }
        for l in 1..=layers {
            let t = (radii[l] - a) / (r_out - a);
            let m = res[l];
            for p in &surface(m).2 {
                let d = p.map(|c| c as f64 / m as f64);
                let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let s = (a * len * (1.0 - t) + r_out * t) / len;
                coords.push(d.map(|c| c * s));
            }
        }
        let mut cells = Vec::new();
        let mut push = |kind: CellKind, nodes: &[u32]| {
            cells.push(positive(Cell::new(kind, nodes), &coords));
        };
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let q = |di: usize, dj: usize, dk: usize| id(0, [i + di, j + dj, k + dk]);
                    push(
                        CellKind::Hex,
                        &[
                            q(0, 0, 0),
                            q(1, 0, 0),
                            q(1, 1, 0),
                            q(0, 1, 0),
                            q(0, 0, 1),
                            q(1, 0, 1),
                            q(1, 1, 1),
                            q(0, 1, 1),
                        ],
                    );
                }
            }
        }
        // Over the face `p[f] = m` of the cube, the point `(u, v)` along the other axes taken in
        // cyclic order.
        let point = |f: usize, m: usize, u: usize, v: usize| {
            let mut p = [0; 3];
            p[f] = m;
            p[(f + 1) % 3] = u;
            p[(f + 2) % 3] = v;
            p
        };
        for l in 0..layers {
            let (inner, outer) = (res[l], res[l + 1]);
            for f in 0..3 {
                for v in 0..outer {
                    for u in 0..outer {
                        let o = |du: usize, dv: usize| id(l + 1, point(f, outer, u + du, v + dv));
                        let [oa, ob, oc, od] = [o(0, 0), o(1, 0), o(1, 1), o(0, 1)];
                        if inner == outer {
                            let i = |du: usize, dv: usize| id(l, point(f, inner, u + du, v + dv));
                            push(
                                CellKind::Hex,
                                &[i(0, 0), i(1, 0), i(1, 1), i(0, 1), oa, ob, oc, od],
                            );
                            continue;
                        }
                        // A 2:1 transition: four inner quads under one outer quad. A pyramid on
                        // each inner quad with its apex at the outer corner above it, a tet on
                        // each side, a pyramid on the outer quad with its apex at the inner
                        // centre: every side face is split the same way from both cells.
                        let i =
                            |du: usize, dv: usize| id(l, point(f, inner, 2 * u + du, 2 * v + dv));
                        let centre = i(1, 1);
                        push(CellKind::Pyramid, &[i(0, 0), i(1, 0), centre, i(0, 1), oa]);
                        push(CellKind::Pyramid, &[i(1, 0), i(2, 0), i(2, 1), centre, ob]);
                        push(CellKind::Pyramid, &[centre, i(2, 1), i(2, 2), i(1, 2), oc]);
                        push(CellKind::Pyramid, &[i(0, 1), centre, i(1, 2), i(0, 2), od]);
                        push(CellKind::Tet, &[i(1, 0), centre, oa, ob]);
                        push(CellKind::Tet, &[i(2, 1), centre, ob, oc]);
                        push(CellKind::Tet, &[i(1, 2), centre, oc, od]);
                        push(CellKind::Tet, &[i(0, 1), centre, od, oa]);
                        push(CellKind::Pyramid, &[oa, ob, oc, od, centre]);
                    }
                }
            }
        }
        let first_outer = first[layers] as u32;
        let mut faces = Vec::new();
        for c in &cells {
            for lf in c.kind.faces() {
                let nodes: Vec<u32> = lf.iter().map(|&l| c.nodes[l]).collect();
                for d in 0..3 {
                    if nodes.iter().all(|&v| coords[v as usize][d] == 0.0) {
                        faces.push(TaggedFace { patch: d as u32, nodes: nodes.clone() });
                    }
                }
                if layers > 0 && nodes.iter().all(|&v| v >= first_outer) {
                    faces.push(TaggedFace { patch: 3, nodes });
                }
            }
        }
        Ok(RawMesh {
            coords,
            cells,
            faces,
            patch_names: PATCH_NAMES.iter().map(|s| s.to_string()).collect(),
            origin: "octant mesh".to_string(),
        })
    }
}

/// The cell with its nodes reordered, if needed, for a positive volume (its faces outward).
fn positive(mut cell: Cell, coords: &[[f64; 3]]) -> Cell {
    let x = |l: usize| coords[cell.nodes[l] as usize];
    let mut six_v = 0.0;
    for face in cell.kind.faces() {
        for k in 1..face.len() - 1 {
            let (p, q, r) = (x(face[0]), x(face[k]), x(face[k + 1]));
            six_v += dot(p, cross(q, r));
        }
    }
    if six_v < 0.0 {
        match cell.kind {
            CellKind::Tet => cell.nodes.swap(1, 2),
            CellKind::Pyramid => cell.nodes.swap(1, 3),
            CellKind::Hex => {
                cell.nodes.swap(1, 3);
                cell.nodes.swap(5, 7);
            }
            CellKind::Prism => {
                cell.nodes.swap(1, 2);
                cell.nodes.swap(4, 5);
            }
        }
    }
    cell
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    fn spec() -> OctantSpec {
        OctantSpec { core: 0.3, cells: 3, fine: 0.5, radius: 4.0, grading: 1.4, coarsen: vec![] }
    }

    #[test]
    fn layers_keep_the_core_spacing_then_grow_to_the_radius() {
        let s = spec();
        let r = s.layer_radii();
        assert_eq!(
            &r[..3].iter().map(|x| (x * 10.0).round()).collect::<Vec<_>>(),
            &[3.0, 4.0, 5.0]
        );
        assert_eq!(*r.last().unwrap(), 4.0);
        for w in r[2..].windows(3) {
            let q = (w[2] - w[1]) / (w[1] - w[0]);
            assert!((q - 1.4).abs() < 1e-12, "grading {q}");
        }
    }

    #[test]
    fn octant_fills_an_eighth_of_the_ball_with_closed_duals() {
        let s = spec();
        let raw = s.raw().unwrap();
        let layers = s.layer_radii().len() - 1;
        assert_eq!(raw.coords.len(), 64 + layers * (64 - 27));
        assert_eq!(s.size(), (raw.coords.len(), raw.cells.len()));
        check_octant(Mesh::build(raw).unwrap(), 0.95);
    }

    #[test]
    fn coarsened_layers_conform_and_close() {
        let s = OctantSpec { cells: 8, coarsen: vec![0.6, 1.2], ..spec() };
        let radii = s.layer_radii();
        let res = s.resolutions(&radii);
        assert_eq!(
            res.iter().filter(|&&m| m == 2).count(),
            res.len() - 1 - res.iter().rposition(|&m| m == 4).unwrap()
        );
        assert!(res.contains(&8) && res.contains(&4) && res.contains(&2), "{res:?}");
        let raw = s.raw().unwrap();
        assert_eq!(s.size(), (raw.coords.len(), raw.cells.len()));
        assert!(raw.cells.iter().any(|c| c.kind == CellKind::Pyramid));
        // Dual closure at every node holds only if every face is shared by exactly two cells
        // (or one and a boundary): a non-conforming transition would leave open duals.
        check_octant(Mesh::build(raw).unwrap(), 0.85);
    }

    /// The mesh fills the octant of radius 4 (to `low` of it: the faceted sphere) with closed
    /// dual cells, its planes and sphere named.
    fn check_octant(mesh: Mesh, low: f64) {
        // The faceted sphere and the cube's corner region: the volume is the ball's octant to the
        // chords' `O(h²)`.
        let octant = std::f64::consts::PI / 6.0 * 4f64.powi(3);
        let v = mesh.total_volume();
        assert!(v < octant && v > low * octant, "volume {v} against {octant}");
        let scale = mesh.dual_areas.iter().cloned().fold(0.0, f64::max);
        for (i, d) in mesh.closure_defects().iter().enumerate() {
            assert!(d.iter().all(|c| c.abs() < 1e-12 * scale), "node {i}: {d:?}");
        }
        for name in PATCH_NAMES {
            mesh.boundary(name).unwrap();
        }
        // The outer boundary's nodes are on the sphere; the planes' on the planes.
        let outer = mesh.boundary("outer").unwrap();
        for &i in &outer.nodes {
            let x = mesh.coords[i as usize];
            let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
            assert!((r - 4.0).abs() < 1e-12, "node {i} at r = {r}");
        }
        for (d, name) in ["xmin", "ymin", "zmin"].iter().enumerate() {
            let b = mesh.boundary(name).unwrap();
            assert!(b.nodes.iter().all(|&i| mesh.coords[i as usize][d] == 0.0));
            // The plane's area: a quarter disc, to the chords.
            let area: f64 = b.normals.iter().map(|n| -n[d]).sum();
            let quarter = std::f64::consts::PI * 16.0 / 4.0;
            assert!(area < quarter && area > low * quarter, "{name}: area {area}");
        }
    }

    #[test]
    fn bad_specs_are_named() {
        for (s, what) in [
            (OctantSpec { cells: 0, ..spec() }, "at least one cell"),
            (OctantSpec { radius: 0.4, ..spec() }, "diagonal"),
            (OctantSpec { grading: 1.0, ..spec() }, "grading"),
            (OctantSpec { coarsen: vec![2.0], ..spec() }, "even"),
            (OctantSpec { cells: 4, coarsen: vec![2.0, 1.0], ..spec() }, "ascend"),
        ] {
            let e = s.raw().unwrap_err().to_string();
            assert!(e.contains(what), "{e}");
        }
    }
}
