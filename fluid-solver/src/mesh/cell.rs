//! Reference cells: local edges and outward-oriented faces of tets, hexes, prisms and pyramids,
//! in gmsh's node ordering.

/// The kinds of volume cells a mesh may hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellKind {
    Tet,
    Hex,
    Prism,
    Pyramid,
}

/// Faces are listed counter-clockwise seen from outside (outward normal by the right-hand rule)
/// for a positively oriented cell.
const TET_FACES: &[&[usize]] = &[&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[2, 0, 3]];
const HEX_FACES: &[&[usize]] =
    &[&[0, 3, 2, 1], &[4, 5, 6, 7], &[0, 1, 5, 4], &[1, 2, 6, 5], &[2, 3, 7, 6], &[3, 0, 4, 7]];
const PRISM_FACES: &[&[usize]] =
    &[&[0, 2, 1], &[3, 4, 5], &[0, 1, 4, 3], &[1, 2, 5, 4], &[2, 0, 3, 5]];
const PYRAMID_FACES: &[&[usize]] = &[&[0, 3, 2, 1], &[0, 1, 4], &[1, 2, 4], &[2, 3, 4], &[3, 0, 4]];

const TET_EDGES: &[[usize; 2]] = &[[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
const HEX_EDGES: &[[usize; 2]] = &[
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 0],
    [4, 5],
    [5, 6],
    [6, 7],
    [7, 4],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];
const PRISM_EDGES: &[[usize; 2]] =
    &[[0, 1], [1, 2], [2, 0], [3, 4], [4, 5], [5, 3], [0, 3], [1, 4], [2, 5]];
const PYRAMID_EDGES: &[[usize; 2]] =
    &[[0, 1], [1, 2], [2, 3], [3, 0], [0, 4], [1, 4], [2, 4], [3, 4]];

/// Per face of a cell whose faces are `faces` and edges `edges`, the local edge along each side
/// of the face (from its node `k` to node `k + 1`); `u8::MAX` past the face's sides.
const fn face_sides(faces: &[&[usize]], edges: &[[usize; 2]]) -> [[u8; 4]; 6] {
    let mut table = [[u8::MAX; 4]; 6];
    let mut f = 0;
    while f < faces.len() {
        let face = faces[f];
        let mut k = 0;
        while k < face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let mut e = 0;
            while e < edges.len() {
                let [p, q] = edges[e];
                if (p == a && q == b) || (p == b && q == a) {
                    table[f][k] = e as u8;
                }
                e += 1;
            }
            k += 1;
        }
        f += 1;
    }
    table
}

static TET_SIDES: [[u8; 4]; 6] = face_sides(TET_FACES, TET_EDGES);
static HEX_SIDES: [[u8; 4]; 6] = face_sides(HEX_FACES, HEX_EDGES);
static PRISM_SIDES: [[u8; 4]; 6] = face_sides(PRISM_FACES, PRISM_EDGES);
static PYRAMID_SIDES: [[u8; 4]; 6] = face_sides(PYRAMID_FACES, PYRAMID_EDGES);

impl CellKind {
    /// Number of nodes.
    pub fn n_nodes(self) -> usize {
        match self {
            CellKind::Tet => 4,
            CellKind::Hex => 8,
            CellKind::Prism => 6,
            CellKind::Pyramid => 5,
        }
    }

    /// Outward-oriented faces as local node lists.
    pub fn faces(self) -> &'static [&'static [usize]] {
        match self {
            CellKind::Tet => TET_FACES,
            CellKind::Hex => HEX_FACES,
            CellKind::Prism => PRISM_FACES,
            CellKind::Pyramid => PYRAMID_FACES,
        }
    }

    /// Local edges.
    pub fn edges(self) -> &'static [[usize; 2]] {
        match self {
            CellKind::Tet => TET_EDGES,
            CellKind::Hex => HEX_EDGES,
            CellKind::Prism => PRISM_EDGES,
            CellKind::Pyramid => PYRAMID_EDGES,
        }
    }

    /// The local edges along the sides of face `f` (from its node `k` to node `k + 1`), one per
    /// node of the face.
    pub fn face_sides(self, f: usize) -> &'static [u8] {
        let table = match self {
            CellKind::Tet => &TET_SIDES,
            CellKind::Hex => &HEX_SIDES,
            CellKind::Prism => &PRISM_SIDES,
            CellKind::Pyramid => &PYRAMID_SIDES,
        };
        &table[f][..self.faces()[f].len()]
    }

    /// Name used in errors and output.
    pub fn name(self) -> &'static str {
        match self {
            CellKind::Tet => "tetrahedron",
            CellKind::Hex => "hexahedron",
            CellKind::Prism => "prism",
            CellKind::Pyramid => "pyramid",
        }
    }
}

/// A volume cell: its kind and global node numbers (only the first `kind.n_nodes()` are used).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cell {
    pub kind: CellKind,
    pub nodes: [u32; 8],
}

impl Cell {
    /// A cell from a node list of the right length.
    pub fn new(kind: CellKind, nodes: &[u32]) -> Cell {
        debug_assert_eq!(nodes.len(), kind.n_nodes());
        let mut n = [u32::MAX; 8];
        n[..nodes.len()].copy_from_slice(nodes);
        Cell { kind, nodes: n }
    }

    /// The used node numbers.
    pub fn nodes(&self) -> &[u32] {
        &self.nodes[..self.kind.n_nodes()]
    }
}

/// The face in which the directed local edge `a -> b` appears in the cycle (the "left" face) and
/// the one in which `b -> a` appears.
pub(crate) fn edge_faces(kind: CellKind, a: usize, b: usize) -> (usize, usize) {
    let mut ab = usize::MAX;
    let mut ba = usize::MAX;
    for (f, face) in kind.faces().iter().enumerate() {
        let n = face.len();
        for k in 0..n {
            let (p, q) = (face[k], face[(k + 1) % n]);
            if p == a && q == b {
                ab = f;
            }
            if p == b && q == a {
                ba = f;
            }
        }
    }
    debug_assert!(ab != usize::MAX && ba != usize::MAX);
    (ab, ba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_edge_is_shared_by_two_faces_in_opposite_directions_and_lies_along_their_sides() {
        for kind in [CellKind::Tet, CellKind::Hex, CellKind::Prism, CellKind::Pyramid] {
            for &[a, b] in kind.edges() {
                let (f1, f2) = edge_faces(kind, a, b);
                assert_ne!(f1, f2, "{kind:?} edge {a}-{b}");
            }
            for (f, face) in kind.faces().iter().enumerate() {
                let sides = kind.face_sides(f);
                assert_eq!(sides.len(), face.len());
                for (k, &e) in sides.iter().enumerate() {
                    let [p, q] = kind.edges()[e as usize];
                    let (a, b) = (face[k], face[(k + 1) % face.len()]);
                    assert!((p, q) == (a, b) || (p, q) == (b, a), "{kind:?} face {f} side {k}");
                }
            }
            // Euler: V - E + F = 2.
            assert_eq!(kind.n_nodes() + kind.faces().len(), kind.edges().len() + 2);
        }
    }
}
