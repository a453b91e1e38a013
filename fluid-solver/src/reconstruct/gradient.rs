//! Nodal least-squares gradients (thesis §3.3.1 reconstruction; the weighted least-squares
//! gradient of the vertex-centred schemes, e.g. SU2's `WEIGHTED_LEAST_SQUARES`).
//!
//! At node `i`, `∇u_i` minimises `Σ_j w_ij (∇u_i · d_ij - (u_j - u_i))²` over its neighbours
//! through edges, `d_ij = x_j - x_i`, `w_ij = 1/|d_ij|²`, so `∇u_i = M_i⁻¹ b_i` with
//! `M_i = Σ_j w_ij d_ij d_ijᵀ` and `b_i = Σ_j w_ij d_ij (u_j - u_i)`. The 3x3 matrices depend on
//! the mesh only: they are inverted once and kept per node (6 numbers, symmetric). The edge term
//! `w_ij d_ij (u_j - u_i)` is the same for both ends (`d_ji = -d_ij`), so one pass over the edges
//! adds it to `b_i` and `b_j` ([`crate::mesh::EdgeBlocks::scatter`]: deterministic, each edge
//! visited once), and each node is multiplied by its `M⁻¹` as soon as its sum is complete. No
//! matrix is built in the time loop and nothing is stored per edge.
//!
//! Edge masks: [`LsqGradient::with_mask`] drops edges (edges cut by the embedded structure, or
//! joining different fluids, DESIGN §5); the matrices of their end nodes are built from the
//! remaining edges. A node whose remaining neighbours do not span 3D gets a zero gradient
//! (first-order reconstruction there). [`LsqGradient::remask`] changes the mask at some edges and
//! rebuilds only the matrices of their end nodes, bitwise as a new build would.
//!
//! # Mirror planes (symmetry planes and plane slip walls)
//!
//! A flow with a symmetry plane of unit normal `n` is the restriction of a flow symmetric under the
//! reflection `R = I - 2nnᵀ`: `ρ(Rx) = ρ(x)`, `p(Rx) = p(x)`, `u(Rx) = R u(x)`. This is the mirror
//! (ghost-node) argument of the symmetry condition: the dummy state outside a symmetry plane is the
//! mirror image of the state inside (Blazek, *Computational Fluid Dynamics: Principles and
//! Applications*, ch. 8, symmetry plane; Greenshields & Weller, *Notes on Computational Fluid
//! Dynamics*, §4.12, with the reflection tensor `I - 2nn`). A plane inviscid slip wall is the same:
//! the reflected flow solves the Euler equations and has `u·n = 0` on the plane (both take the same
//! flux, [`crate::bc`]), so both get this treatment; far-field, inflow and outflow patches never
//! do. At a node on the plane the exact gradients then satisfy `∇ρ = R∇ρ`, `∇p = R∇p` and
//! `∇u = R ∇u R` (`∇u[k][a] = ∂u_k/∂x_a`): the normal derivatives of ρ, p and the tangential
//! velocity vanish, and so do the tangential derivatives of `u·n`. The one-sided stencil of a
//! boundary node does not know this: on the lopsided stencils of tets split from hexes, a 1D
//! flow along a symmetry plane gets gradient components normal to it, which MUSCL turns into a
//! spurious transverse velocity at strong contacts.
//!
//! The operator here is the least-squares gradient over the stencil completed by its mirror
//! image: each neighbour `j` gets a ghost at `R x_j` with the mirrored difference (`Δρ`, `Δp`,
//! `R Δu`). Its matrix is `M + R M R`, which commutes with `R`, and its right-hand side the
//! symmetric part of `b`, so the gradient is `S(M̄⁻¹ b)` with `M̄ = (M + R M R)/2` and the
//! symmetric part `S(g) = (g + R g)/2 = g - (g·n) n` of a scalar gradient, `S(G) = (G + R G R)/2`
//! of the velocity gradient (`R` on both indices). `M̄⁻¹` replaces `M⁻¹` in the kept inverses, so
//! the time loop only adds `S` at the nodes on planes (the same work as projecting the plain
//! gradient with `S`). Projection alone would also respect the symmetry, but it keeps the
//! coupling of the one-sided `M` between the normal and tangential directions, so its
//! tangential components are not those of any mirror-symmetric fit; the mirrored stencil is the
//! least-squares fit of the ghost-node argument itself, and at a node on two perpendicular
//! planes (every node of a one-cell-thick tube) it is exactly the 1D fit along the tube. On the
//! tet shock tubes the two give the same star states and L1 errors to 0.3%. The mirrored
//! differences assume `u_i·n = 0` at the node, which the wall flux imposes weakly.
//!
//! The planes are found once ([`MirrorPlanes::new`]): a node of a mirror patch takes its dual
//! boundary normal as the plane normal if every neighbour through an edge that lies on the same
//! patch is in that plane (to `1e-6` of the edge length). Nodes on curved parts of a patch, or
//! on a crease inside one patch, keep their plain gradient (there is no mirror image there: the
//! pressure gradient normal to a curved wall balances the centripetal acceleration); split such
//! patches into planar ones. A node on several planes (of several patches) gets each of them
//! in the fixed order of the patches in the mesh: `M` is symmetrised for the first plane, then
//! for the second, and `S` is applied in the same order. For perpendicular planes the
//! reflections commute, and this is exactly the stencil completed by all its images (three
//! ghosts per neighbour for two planes). For planes at other angles no mirror image is
//! consistent with both (the images do not close): the result is exactly symmetric about the
//! last plane and only approximately about the earlier ones, a compromise at what is a corner
//! of the domain anyway.

use crate::mesh::geometry::{dot, norm, scale, sub};
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::ops::Range;

/// The components of a field with mirror planes that form the velocity vector (the primitive
/// variables `[ρ, u, v, w, p]`); every other component is a scalar, even under reflections.
pub const VELOCITY: Range<usize> = 1..4;

/// Largest distance of an in-patch neighbour from a node's plane, relative to the edge length,
/// for the node to count as lying on a plane of its patch.
const PLANE_TOLERANCE: f64 = 1e-6;

/// Precomputed least-squares gradient operator of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct LsqGradient {
    /// Per node, `M_i⁻¹` (`M̄_i⁻¹` at nodes on mirror planes) as `[xx, xy, xz, yy, yz, zz]`
    /// (zero where the matrix is singular).
    inverses: Vec<[f64; 6]>,
    /// Per edge, whether it takes part (`None`: all edges).
    mask: Option<Vec<bool>>,
    planes: MirrorPlanes,
}

/// The mirror planes of the nodes on planar symmetry and slip-wall patches (module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MirrorPlanes {
    /// Nodes on a plane, ascending; a node on `k` planes appears `k` times, in patch order.
    nodes: Vec<u32>,
    /// The unit normal of each entry's plane.
    normals: Vec<[f64; 3]>,
}

impl MirrorPlanes {
    /// The planes of the nodes of the boundaries `patches` (indices in `mesh.boundaries`, taken
    /// in ascending order) where those are planar.
    pub fn new(mesh: &Mesh, patches: &[usize]) -> MirrorPlanes {
        let mut patches = patches.to_vec();
        patches.sort_unstable();
        patches.dedup();
        let mut entries: Vec<(u32, usize, [f64; 3])> = Vec::new();
        let mut slot = vec![u32::MAX; mesh.n_nodes()];
        for &p in &patches {
            let boundary = &mesh.boundaries[p];
            for (k, &i) in boundary.nodes.iter().enumerate() {
                slot[i as usize] = k as u32;
            }
            let unit: Vec<[f64; 3]> =
                boundary.normals.iter().map(|&n| scale(n, 1.0 / norm(n))).collect();
            let mut planar = vec![true; boundary.nodes.len()];
            for &[i, j] in &mesh.edges {
                let (ki, kj) = (slot[i as usize], slot[j as usize]);
                if ki == u32::MAX || kj == u32::MAX {
                    continue;
                }
                let d = sub(mesh.coords[j as usize], mesh.coords[i as usize]);
                let tol = PLANE_TOLERANCE * norm(d);
                for k in [ki as usize, kj as usize] {
                    if dot(d, unit[k]).abs() > tol {
                        planar[k] = false;
                    }
                }
            }
            for (k, &i) in boundary.nodes.iter().enumerate() {
                slot[i as usize] = u32::MAX;
                if planar[k] && unit[k].iter().all(|c| c.is_finite()) {
                    entries.push((i, p, unit[k]));
                }
            }
        }
        // By node, then in patch order (the order they were pushed).
        entries.sort_by_key(|e| (e.0, e.1));
        MirrorPlanes {
            nodes: entries.iter().map(|e| e.0).collect(),
            normals: entries.iter().map(|e| e.2).collect(),
        }
    }

    /// Number of (node, plane) pairs.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Every node on a plane with its planes' unit normals, in patch order; nodes ascending.
    pub fn by_node(&self) -> impl Iterator<Item = (usize, &[[f64; 3]])> {
        let mut start = 0;
        self.nodes.chunk_by(|a, b| a == b).map(move |run| {
            let range = start..start + run.len();
            start = range.end;
            (run[0] as usize, &self.normals[range])
        })
    }

    /// The planes of node `i`, in patch order.
    fn of_node(&self, i: usize) -> &[[f64; 3]] {
        &self.normals[self.entries(&(i..i + 1))]
    }

    /// The entries of the nodes in `nodes`.
    fn entries(&self, nodes: &Range<usize>) -> Range<usize> {
        self.nodes.partition_point(|&v| (v as usize) < nodes.start)
            ..self.nodes.partition_point(|&v| (v as usize) < nodes.end)
    }
}

/// `(A + R A R)/2` for the reflection `R = I - 2nnᵀ` of unit normal `n`, in place:
/// `A - n (Aᵀn)ᵀ - (A n) nᵀ + 2 (nᵀA n) n nᵀ` (the part of `A` even under the reflection of both
/// indices: the symmetrised least-squares matrix, or the mirror-symmetric velocity gradient).
#[inline]
fn mirror_symmetric(a: &mut [[f64; 3]; 3], n: &[f64; 3]) {
    let an: [f64; 3] = std::array::from_fn(|k| dot(a[k], *n));
    let na: [f64; 3] = std::array::from_fn(|c| n[0] * a[0][c] + n[1] * a[1][c] + n[2] * a[2][c]);
    let s = dot(an, *n);
    for k in 0..3 {
        for c in 0..3 {
            a[k][c] += 2.0 * s * n[k] * n[c] - n[k] * na[c] - an[k] * n[c];
        }
    }
}

/// The mirror-symmetric part of the gradients `g` of an `N`-component field at a node on the
/// plane of unit normal `n`: `g - (g·n) n` for scalars, [`mirror_symmetric`] for [`VELOCITY`].
#[inline]
fn mirror_gradient<const N: usize>(g: &mut [[f64; 3]; N], n: &[f64; 3]) {
    let vector = N >= VELOCITY.end;
    for (k, gk) in g.iter_mut().enumerate() {
        if !(vector && VELOCITY.contains(&k)) {
            let gn = dot(*gk, *n);
            *gk = [gk[0] - gn * n[0], gk[1] - gn * n[1], gk[2] - gn * n[2]];
        }
    }
    if vector {
        let mut v = [g[VELOCITY.start], g[VELOCITY.start + 1], g[VELOCITY.start + 2]];
        mirror_symmetric(&mut v, n);
        g[VELOCITY].copy_from_slice(&v);
    }
}

/// Inverse of a symmetric 3x3 matrix, or `None` if it is singular relative to its size.
fn invert_sym3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    let c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    let c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    let det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    let trace = m[0][0] + m[1][1] + m[2][2];
    if det.abs().partial_cmp(&(1e-10 * trace * trace * trace)).is_none_or(|o| o.is_le()) {
        return None;
    }
    let inv = 1.0 / det;
    let c11 = m[0][0] * m[2][2] - m[0][2] * m[2][0];
    let c12 = m[0][1] * m[2][0] - m[0][0] * m[2][1];
    let c22 = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    Some([
        [c00 * inv, c01 * inv, c02 * inv],
        [c01 * inv, c11 * inv, c12 * inv],
        [c02 * inv, c12 * inv, c22 * inv],
    ])
}

/// Adds the term `w d dᵀ` of the edge `(i, j)` (`d = x_j - x_i`, `w = 1/|d|²`) to `m`.
#[inline]
fn add_edge_moment(m: &mut [[f64; 3]; 3], mesh: &Mesh, [i, j]: [u32; 2]) {
    let d = sub(mesh.coords[j as usize], mesh.coords[i as usize]);
    let w = 1.0 / dot(d, d);
    for a in 0..3 {
        for b in 0..3 {
            m[a][b] += w * d[a] * d[b];
        }
    }
}

/// The least-squares term of edge `i -> j` (added to both ends): `w d (u_j - u_i)` for each
/// component, `d = x_j - x_i`, `w = 1/|d|²`.
#[inline(always)]
fn edge_term<const N: usize>(
    mesh: &Mesh,
    values: &[[f64; N]],
    i: usize,
    j: usize,
) -> [[f64; 3]; N] {
    let d = sub(mesh.coords[j], mesh.coords[i]);
    let w = 1.0 / dot(d, d);
    let wd = scale(d, w);
    let (ui, uj) = (&values[i], &values[j]);
    std::array::from_fn(|k| {
        let du = uj[k] - ui[k];
        [wd[0] * du, wd[1] * du, wd[2] * du]
    })
}

/// `g_k <- M⁻¹ g_k` for every component, `M⁻¹` packed as by [`packed_inverse`].
#[inline(always)]
fn apply_inverse<const N: usize>(m: &[f64; 6], g: &mut [[f64; 3]; N]) {
    for gk in g.iter_mut() {
        let v = *gk;
        *gk = [
            m[0] * v[0] + m[1] * v[1] + m[2] * v[2],
            m[1] * v[0] + m[3] * v[1] + m[4] * v[2],
            m[2] * v[0] + m[4] * v[1] + m[5] * v[2],
        ];
    }
}

/// `M⁻¹` as `[xx, xy, xz, yy, yz, zz]`, zero where `M` is singular.
fn packed_inverse(m: &[[f64; 3]; 3]) -> [f64; 6] {
    invert_sym3(m).map_or([0.0; 6], |v| [v[0][0], v[0][1], v[0][2], v[1][1], v[1][2], v[2][2]])
}

impl LsqGradient {
    /// The operator using every edge, without mirror planes.
    pub fn new(mesh: &Mesh) -> LsqGradient {
        Self::with_mask(mesh, None)
    }

    /// The operator using only the edges `e` with `mask[e] == true` (all when `None`), without
    /// mirror planes.
    pub fn with_mask(mesh: &Mesh, mask: Option<&[bool]>) -> LsqGradient {
        Self::with_planes(mesh, mask, MirrorPlanes::default())
    }

    /// The operator using the edges of `mask` (all when `None`), with the mirror stencils of
    /// `planes` at their nodes (module docs).
    pub fn with_planes(mesh: &Mesh, mask: Option<&[bool]>, planes: MirrorPlanes) -> LsqGradient {
        let mut m = vec![[[0.0; 3]; 3]; mesh.n_nodes()];
        for (e, &[i, j]) in mesh.edges.iter().enumerate() {
            if mask.is_some_and(|m| !m[e]) {
                continue;
            }
            for node in [i as usize, j as usize] {
                add_edge_moment(&mut m[node], mesh, [i, j]);
            }
        }
        for (&i, n) in planes.nodes.iter().zip(&planes.normals) {
            mirror_symmetric(&mut m[i as usize], n);
        }
        let inverses = m.par_iter().map(packed_inverse).collect();
        LsqGradient { inverses, mask: mask.map(<[bool]>::to_vec), planes }
    }

    /// Flips the mask at the edges `flipped` (each listed once) and rebuilds the matrices of
    /// their end nodes from their edges `edges_of(i)` (ascending, every edge of `i`), so that the
    /// operator is bitwise the one [`LsqGradient::with_planes`] builds with the new mask: the
    /// same sums in the same (edge) order, then the same planes and inversion.
    pub fn remask<'a>(
        &mut self,
        mesh: &Mesh,
        flipped: &[u32],
        edges_of: impl Fn(usize) -> &'a [u32] + Sync,
    ) {
        if flipped.is_empty() {
            return;
        }
        let mask = self.mask.get_or_insert_with(|| vec![true; mesh.n_edges()]);
        let mut nodes = Vec::with_capacity(2 * flipped.len());
        for &e in flipped {
            mask[e as usize] = !mask[e as usize];
            nodes.extend(mesh.edges[e as usize]);
        }
        nodes.sort_unstable();
        nodes.dedup();
        let (mask, planes) = (&*mask, &self.planes);
        let rebuilt: Vec<[f64; 6]> = nodes
            .par_iter()
            .map(|&i| {
                let i = i as usize;
                let mut m = [[0.0; 3]; 3];
                for &e in edges_of(i) {
                    if mask[e as usize] {
                        add_edge_moment(&mut m, mesh, mesh.edges[e as usize]);
                    }
                }
                for n in planes.of_node(i) {
                    mirror_symmetric(&mut m, n);
                }
                packed_inverse(&m)
            })
            .collect();
        for (&i, inv) in nodes.iter().zip(rebuilt) {
            self.inverses[i as usize] = inv;
        }
    }

    /// Whether edge `e` takes part.
    pub fn uses(&self, e: usize) -> bool {
        self.mask.as_ref().is_none_or(|m| m[e])
    }

    /// The mirror planes of the operator.
    pub fn planes(&self) -> &MirrorPlanes {
        &self.planes
    }

    /// Gradients of `N`-component nodal fields: `grad[i][k] = ∇ values[i][k]` (with mirror
    /// planes, components [`VELOCITY`] are the velocity).
    pub fn compute<const N: usize>(
        &self,
        mesh: &Mesh,
        values: &[[f64; N]],
        grad: &mut [[[f64; 3]; N]],
    ) {
        let blocks = &mesh.blocks;
        let result = blocks.scatter(grad, |b, g| {
            for i in blocks.fresh(b) {
                g[i] = [[0.0; 3]; N];
            }
            for e in blocks.edges(b) {
                if self.mask.as_ref().is_some_and(|m| !m[e]) {
                    continue;
                }
                let [i, j] = mesh.edges[e];
                let (i, j) = (i as usize, j as usize);
                let t = edge_term(mesh, values, i, j);
                for k in 0..N {
                    for a in 0..3 {
                        g[i][k][a] += t[k][a];
                    }
                }
                for k in 0..N {
                    for a in 0..3 {
                        g[j][k][a] += t[k][a];
                    }
                }
            }
            for i in blocks.completed(b) {
                apply_inverse(&self.inverses[i], &mut g[i]);
            }
            let done = blocks.completed(b);
            for e in self.planes.entries(&done) {
                mirror_gradient(&mut g[self.planes.nodes[e] as usize], &self.planes.normals[e]);
            }
            Ok::<(), std::convert::Infallible>(())
        });
        let Ok(()) = result;
    }

    /// [`LsqGradient::compute`] at the nodes `nodes` only (the other entries of `grad` are left
    /// as they are), from each node's edges `edges_of(i)` (ascending, every edge of `i`): bitwise
    /// the full pass's gradients there, the same terms summed in the same (edge) order. For the
    /// few nodes a step reads outside its stages (the ends of cut edges).
    pub fn compute_at<'a, const N: usize>(
        &self,
        mesh: &Mesh,
        values: &[[f64; N]],
        nodes: &[u32],
        edges_of: impl Fn(usize) -> &'a [u32] + Sync,
        grad: &mut [[[f64; 3]; N]],
    ) {
        let at: Vec<[[f64; 3]; N]> = nodes
            .par_iter()
            .map(|&i| {
                let i = i as usize;
                let mut g = [[0.0; 3]; N];
                for &e in edges_of(i) {
                    if !self.uses(e as usize) {
                        continue;
                    }
                    let [a, b] = mesh.edges[e as usize].map(|v| v as usize);
                    let t = edge_term(mesh, values, a, b);
                    for k in 0..N {
                        for c in 0..3 {
                            g[k][c] += t[k][c];
                        }
                    }
                }
                apply_inverse(&self.inverses[i], &mut g);
                for n in self.planes.of_node(i) {
                    mirror_gradient(&mut g, n);
                }
                g
            })
            .collect();
        for (&i, g) in nodes.iter().zip(at) {
            grad[i as usize] = g;
        }
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.inverses[..])
            + std::mem::size_of_val(&self.planes.nodes[..])
            + std::mem::size_of_val(&self.planes.normals[..])
            + self.mask.as_ref().map_or(0, |m| std::mem::size_of_val(&m[..]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec};
    use crate::mesh::{perturb, RawMesh};

    /// Boundary index of a box face.
    fn face(mesh: &Mesh, name: &str) -> usize {
        mesh.boundaries.iter().position(|b| b.name == name).unwrap()
    }

    fn perturbed_box(cells: [usize; 3]) -> RawMesh {
        let mut raw =
            BoxSpec::uniform([0.0; 3], [1.0, 0.8, 0.6], cells, BoxCells::Tet).raw().unwrap();
        perturb(&mut raw, 0.2, 7);
        raw
    }

    /// A smooth field with no symmetry: `[ρ, u, v, w, p]`.
    fn wavy(x: [f64; 3]) -> [f64; 5] {
        let s = (3.0 * x[0] + 2.0 * x[1] - x[2]).sin();
        let c = (2.0 * x[0] - x[1] + 4.0 * x[2]).cos();
        [1.0 + 0.3 * s, 0.2 * c + x[1], -0.1 * s + x[2] * x[0], 0.3 * s * c, 1.0 + 0.2 * c * x[1]]
    }

    fn reflect(v: [f64; 3], n: [f64; 3]) -> [f64; 3] {
        let vn = dot(v, n);
        [v[0] - 2.0 * vn * n[0], v[1] - 2.0 * vn * n[1], v[2] - 2.0 * vn * n[2]]
    }

    /// The least-squares gradient at node `i` of the stencil completed by the images of every
    /// neighbour under the group of the perpendicular reflections `normals`, built directly.
    fn ghost_fit(
        mesh: &Mesh,
        values: &[[f64; 5]],
        i: usize,
        normals: &[[f64; 3]],
    ) -> [[f64; 3]; 5] {
        let mut images: Vec<Vec<[f64; 3]>> = vec![vec![]];
        for &n in normals {
            let more: Vec<Vec<[f64; 3]>> =
                images.iter().map(|g| g.iter().copied().chain([n]).collect()).collect();
            images.extend(more);
        }
        let apply = |g: &[[f64; 3]], v: [f64; 3]| g.iter().fold(v, |v, &n| reflect(v, n));
        let mut m = [[0.0; 3]; 3];
        let mut b = [[0.0; 3]; 5];
        for &[p, q] in &mesh.edges {
            let j = match (p as usize, q as usize) {
                (p, q) if p == i => q,
                (p, q) if q == i => p,
                _ => continue,
            };
            let d0 = sub(mesh.coords[j], mesh.coords[i]);
            let du0: [f64; 5] = std::array::from_fn(|k| values[j][k] - values[i][k]);
            for g in &images {
                let d = apply(g, d0);
                let u = apply(g, [du0[1], du0[2], du0[3]]);
                let du = [du0[0], u[0], u[1], u[2], du0[4]];
                let w = 1.0 / dot(d, d);
                for a in 0..3 {
                    for c in 0..3 {
                        m[a][c] += w * d[a] * d[c];
                    }
                    for k in 0..5 {
                        b[k][a] += w * d[a] * du[k];
                    }
                }
            }
        }
        let inv = invert_sym3(&m).unwrap();
        std::array::from_fn(|k| std::array::from_fn(|a| dot(inv[a], b[k])))
    }

    #[test]
    fn gradients_on_planes_are_the_fits_of_the_mirrored_stencils() {
        let mesh = Mesh::build(perturbed_box([5, 4, 4])).unwrap();
        let (ymin, zmin) = (face(&mesh, "ymin"), face(&mesh, "zmin"));
        let planes = MirrorPlanes::new(&mesh, &[zmin, ymin]);
        let y_nodes = &mesh.boundaries[ymin].nodes;
        let z_nodes = &mesh.boundaries[zmin].nodes;
        assert_eq!(planes.len(), y_nodes.len() + z_nodes.len(), "both faces are planar");
        let lsq = LsqGradient::with_planes(&mesh, None, planes);
        let values: Vec<[f64; 5]> = mesh.coords.iter().map(|&x| wavy(x)).collect();
        let mut grad = vec![[[0.0; 3]; 5]; mesh.n_nodes()];
        lsq.compute(&mesh, &values, &mut grad);
        let (ny, nz) = ([0.0, -1.0, 0.0], [0.0, 0.0, -1.0]);
        let (mut on_one, mut on_both) = (0, 0);
        for i in 0..mesh.n_nodes() {
            let (y, z) = (y_nodes.contains(&(i as u32)), z_nodes.contains(&(i as u32)));
            let normals: Vec<[f64; 3]> = match (y, z) {
                (false, false) => vec![],
                (true, false) => vec![ny],
                (false, true) => vec![nz],
                (true, true) => vec![ny, nz],
            };
            on_one += usize::from(normals.len() == 1);
            on_both += usize::from(normals.len() == 2);
            let fit = ghost_fit(&mesh, &values, i, &normals);
            for k in 0..5 {
                for a in 0..3 {
                    assert!(
                        (grad[i][k][a] - fit[k][a]).abs() < 1e-11,
                        "node {i} {normals:?}: ∂{k}/∂x{a} = {}, mirrored fit {}",
                        grad[i][k][a],
                        fit[k][a]
                    );
                }
            }
            // The mirror conditions: no ∂/∂y of ρ, p, u, w and no ∂v/∂x, ∂v/∂z on y = 0.
            if y {
                for (k, a) in [(0, 1), (4, 1), (1, 1), (3, 1), (2, 0), (2, 2)] {
                    assert!(
                        grad[i][k][a].abs() < 1e-12,
                        "node {i}: ∂{k}/∂x{a} = {}",
                        grad[i][k][a]
                    );
                }
            }
        }
        assert!(on_one > 20 && on_both >= 6, "{on_one} nodes on one plane, {on_both} on both");
    }

    #[test]
    fn gradients_at_some_nodes_are_the_full_pass_bitwise() {
        let mesh = Mesh::build(perturbed_box([5, 4, 4])).unwrap();
        let planes = MirrorPlanes::new(&mesh, &[face(&mesh, "zmin"), face(&mesh, "ymin")]);
        let mask: Vec<bool> = (0..mesh.n_edges()).map(|e| e % 3 != 1).collect();
        let lsq = LsqGradient::with_planes(&mesh, Some(&mask), planes);
        let values: Vec<[f64; 5]> = mesh.coords.iter().map(|&x| wavy(x)).collect();
        let mut full = vec![[[0.0; 3]; 5]; mesh.n_nodes()];
        lsq.compute(&mesh, &values, &mut full);
        let mut edges_of = vec![vec![]; mesh.n_nodes()];
        for (e, &[i, j]) in mesh.edges.iter().enumerate() {
            edges_of[i as usize].push(e as u32);
            edges_of[j as usize].push(e as u32);
        }
        let nodes: Vec<u32> = (0..mesh.n_nodes() as u32).filter(|i| i % 4 == 0).collect();
        let mut some = vec![[[7.0; 3]; 5]; mesh.n_nodes()];
        lsq.compute_at(&mesh, &values, &nodes, |i| &edges_of[i], &mut some);
        for i in 0..mesh.n_nodes() {
            let expected = if i % 4 == 0 { full[i] } else { [[7.0; 3]; 5] };
            assert_eq!(some[i], expected, "node {i}");
        }
        assert!(nodes.iter().any(|&i| !lsq.planes().of_node(i as usize).is_empty()));
    }

    #[test]
    fn gradients_on_a_one_cell_thick_tube_have_no_sideways_components() {
        let mesh =
            Mesh::build(BoxSpec::tube(0.0, 1.0, 20, 0.05, BoxCells::Tet).raw().unwrap()).unwrap();
        let sides: Vec<usize> =
            ["ymin", "ymax", "zmin", "zmax"].iter().map(|f| face(&mesh, f)).collect();
        let lsq = LsqGradient::with_planes(&mesh, None, MirrorPlanes::new(&mesh, &sides));
        // Every node of the tube lies on two perpendicular planes.
        assert_eq!(lsq.planes().len(), 2 * mesh.n_nodes());
        // A field quadratic in x: the plain fit on the one-sided tet stencils tilts it sideways,
        // the mirrored one does not; a field linear in x stays exact.
        let fields = [
            |x: f64| [1.0 + 2.0 * x * x, 3.0 * x * x, 0.0, 0.0, 2.0 - x * x],
            |x: f64| [1.0 + 2.0 * x, 3.0 * x, 0.0, 0.0, 2.0 - x],
        ];
        let mut grad = vec![[[0.0; 3]; 5]; mesh.n_nodes()];
        let mut plain = grad.clone();
        let sideways = |g: &[[[f64; 3]; 5]]| {
            g.iter()
                .flat_map(|g| g.iter().flat_map(|c| [c[1].abs(), c[2].abs()]))
                .fold(0.0, f64::max)
        };
        for (k, f) in fields.iter().enumerate() {
            let values: Vec<[f64; 5]> = mesh.coords.iter().map(|x| f(x[0])).collect();
            lsq.compute(&mesh, &values, &mut grad);
            LsqGradient::new(&mesh).compute(&mesh, &values, &mut plain);
            if k == 0 {
                assert!(sideways(&plain) > 0.01, "the plain fit tilts: {}", sideways(&plain));
            }
            assert!(sideways(&grad) < 1e-12, "{}", sideways(&grad));
        }
        assert!(grad
            .iter()
            .all(|g| (0..5).all(|k| (g[k][0] - [2.0, 3.0, 0.0, 0.0, -1.0][k]).abs() < 1e-12)));
    }

    #[test]
    fn creases_inside_a_patch_and_curved_patches_get_no_plane() {
        // ymin and zmin joined into one patch: a crease along x at y = z = 0.
        let mut raw = perturbed_box([4, 4, 4]);
        for f in &mut raw.faces {
            if f.patch == 4 {
                f.patch = 2;
            }
        }
        let mesh = Mesh::build(raw).unwrap();
        let walls = face(&mesh, "ymin");
        let planes = MirrorPlanes::new(&mesh, &[walls]);
        let on_crease = |i: u32| {
            let x = mesh.coords[i as usize];
            x[1].abs() < 1e-12 && x[2].abs() < 1e-12
        };
        let nodes = &mesh.boundaries[walls].nodes;
        let expected: Vec<u32> = nodes.iter().copied().filter(|&i| !on_crease(i)).collect();
        assert_eq!(planes.nodes, expected);
        for (&i, n) in planes.nodes.iter().zip(&planes.normals) {
            let x = mesh.coords[i as usize];
            let want = if x[1].abs() < 1e-12 { [0.0, -1.0, 0.0] } else { [0.0, 0.0, -1.0] };
            assert!(n.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12), "node {i}: {n:?}");
        }
        // A face bent along x (straight along z): only the nodes of its two end lines x = 0, 1,
        // whose facets all lie in one flat strip, are on a plane.
        let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [4, 4, 4], BoxCells::Tet).raw().unwrap();
        for x in &mut raw.coords {
            x[1] += 0.05 * (x[0] - 0.5).powi(2) * (1.0 - x[1]);
        }
        let mesh = Mesh::build(raw).unwrap();
        let planes = MirrorPlanes::new(&mesh, &[face(&mesh, "ymin")]);
        let ends = |i: &u32| {
            let x = mesh.coords[*i as usize][0];
            x == 0.0 || x == 1.0
        };
        assert_eq!(planes.len(), 10);
        assert!(planes.nodes.iter().all(ends));
    }
}
