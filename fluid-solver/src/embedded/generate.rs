//! Generated embedded surfaces for fluid-alone runs (`[fluid.embedded] surface = { generator = ..}`):
//! icosphere, closed box, open plate, cylinder. Closed surfaces are wound so that the right-hand
//! normal of every element points outwards; the plate's normal is `edge_u × edge_v`.

use interface_protocol::case::SurfaceGenerator;
use interface_protocol::messages::SurfaceElement;

/// Nodes and elements of a surface (elements index the nodes, protocol layout).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceMesh {
    pub x: Vec<[f64; 3]>,
    pub elements: Vec<SurfaceElement>,
}

impl SurfaceMesh {
    fn tri(&mut self, a: usize, b: usize, c: usize) {
        let nodes = [a as u32, b as u32, c as u32, 0];
        self.elements.push(SurfaceElement { nodes, n_nodes: 3, ..Default::default() });
    }

    fn quad(&mut self, a: usize, b: usize, c: usize, d: usize) {
        let nodes = [a as u32, b as u32, c as u32, d as u32];
        self.elements.push(SurfaceElement { nodes, n_nodes: 4, ..Default::default() });
    }

    /// Node of `p`, reusing an existing one at the same position (generators share corners).
    fn node(
        &mut self,
        p: [f64; 3],
        index: &mut std::collections::HashMap<[u64; 3], usize>,
    ) -> usize {
        *index.entry(p.map(|v| (v + 0.0).to_bits())).or_insert_with(|| {
            self.x.push(p);
            self.x.len() - 1
        })
    }
}

/// The surface of a generator.
pub fn generate(g: &SurfaceGenerator) -> SurfaceMesh {
    match *g {
        SurfaceGenerator::Sphere { center, radius, refinement } => {
            sphere(center, radius, refinement)
        }
        SurfaceGenerator::Box { lo, hi, cells } => closed_box(lo, hi, cells),
        SurfaceGenerator::Plate { corner, edge_u, edge_v, cells } => {
            plate(corner, edge_u, edge_v, cells)
        }
        SurfaceGenerator::Cylinder { start, end, radius, cells, capped } => {
            cylinder(start, end, radius, cells, capped)
        }
    }
}

/// An icosphere: the icosahedron, each triangle split in four `refinement` times, nodes
/// projected to the sphere.
pub fn sphere(center: [f64; 3], radius: f64, refinement: u32) -> SurfaceMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut unit: Vec<[f64; 3]> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .into_iter()
    .map(normalise)
    .collect();
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..refinement {
        let mut mid = std::collections::HashMap::new();
        let mut midpoint = |a: usize, b: usize, unit: &mut Vec<[f64; 3]>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (unit[a], unit[b]);
                unit.push(normalise([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                unit.len() - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let (ab, bc, ca) =
                (midpoint(a, b, &mut unit), midpoint(b, c, &mut unit), midpoint(c, a, &mut unit));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let mut s = SurfaceMesh {
        x: unit.iter().map(|u| [0, 1, 2].map(|k| center[k] + radius * u[k])).collect(),
        elements: Vec::new(),
    };
    for [a, b, c] in faces {
        s.tri(a, b, c);
    }
    s
}

fn normalise(p: [f64; 3]) -> [f64; 3] {
    let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    p.map(|v| v / n)
}

/// A flat quad grid `corner + (i/nu) edge_u + (j/nv) edge_v`, normal `edge_u × edge_v`, appended
/// to `s` with shared nodes merged through `index`.
fn grid(
    s: &mut SurfaceMesh,
    index: &mut std::collections::HashMap<[u64; 3], usize>,
    corner: [f64; 3],
    edge_u: [f64; 3],
    edge_v: [f64; 3],
    [nu, nv]: [u32; 2],
) {
    let at = |i: u32, j: u32| {
        let (a, b) = (i as f64 / nu as f64, j as f64 / nv as f64);
        [0, 1, 2].map(|k| corner[k] + a * edge_u[k] + b * edge_v[k])
    };
    for j in 0..nv {
        for i in 0..nu {
            let q =
                [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)].map(|p| s.node(p, index));
            s.quad(q[0], q[1], q[2], q[3]);
        }
    }
}

/// An open plate, `cells = [along edge_u, along edge_v]` quads.
pub fn plate(corner: [f64; 3], edge_u: [f64; 3], edge_v: [f64; 3], cells: [u32; 2]) -> SurfaceMesh {
    let mut s = SurfaceMesh::default();
    grid(&mut s, &mut Default::default(), corner, edge_u, edge_v, cells);
    s
}

/// The six faces of the box `[lo, hi]`, outward normals, `cells` quads per axis.
pub fn closed_box(lo: [f64; 3], hi: [f64; 3], cells: [u32; 3]) -> SurfaceMesh {
    let mut s = SurfaceMesh::default();
    let mut index = Default::default();
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut eu = [0.0; 3];
        let mut ev = [0.0; 3];
        eu[u] = hi[u] - lo[u];
        ev[v] = hi[v] - lo[v];
        // The face at hi[axis] has normal eu × ev = +axis; the face at lo[axis] swaps u and v.
        let mut top = lo;
        top[axis] = hi[axis];
        grid(&mut s, &mut index, top, eu, ev, [cells[u], cells[v]]);
        grid(&mut s, &mut index, lo, ev, eu, [cells[v], cells[u]]);
    }
    s
}

/// A cylinder of `cells[0]` facets around and `cells[1]` along, outward normals; with end caps
/// (triangle fans about the axis ends) when `capped`.
pub fn cylinder(
    start: [f64; 3],
    end: [f64; 3],
    radius: f64,
    cells: [u32; 2],
    capped: bool,
) -> SurfaceMesh {
    let axis = [end[0] - start[0], end[1] - start[1], end[2] - start[2]];
    let a = normalise(axis);
    // Two unit vectors normal to the axis, (e1, e2, a) right-handed.
    let trial = if a[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let e1 = normalise(cross(trial, a));
    let e2 = cross(a, e1);
    let (n_around, n_along) = (cells[0] as usize, cells[1] as usize);
    let mut s = SurfaceMesh::default();
    for j in 0..=n_along {
        let f = j as f64 / n_along as f64;
        for i in 0..n_around {
            let th = std::f64::consts::TAU * i as f64 / n_around as f64;
            let (c, sn) = (th.cos(), th.sin());
            s.x.push([0, 1, 2].map(|k| start[k] + f * axis[k] + radius * (c * e1[k] + sn * e2[k])));
        }
    }
    let id = |i: usize, j: usize| j * n_around + i % n_around;
    for j in 0..n_along {
        for i in 0..n_around {
            // Around (e1 -> e2) then along a: (e1 × a) points inwards, so wind i+1 before j+1.
            s.quad(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
        }
    }
    if capped {
        let c0 = s.x.len();
        s.x.push(start);
        s.x.push(end);
        for i in 0..n_around {
            s.tri(c0, id(i + 1, 0), id(i, 0));
            s.tri(c0 + 1, id(i, n_along), id(i + 1, n_along));
        }
    }
    s
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Σ_e A_e n_e` (zero for a closed surface) and the enclosed volume `Σ_e (x_e · A_e n_e)/3`
    /// (divergence theorem: positive when the normals point outwards).
    fn closure_and_volume(s: &SurfaceMesh) -> ([f64; 3], f64) {
        let mut area = [0.0; 3];
        let mut volume = 0.0;
        for e in &s.elements {
            let n = e.n_nodes as usize;
            for k in 1..n - 1 {
                let (p, q, r) = (
                    s.x[e.nodes[0] as usize],
                    s.x[e.nodes[k] as usize],
                    s.x[e.nodes[k + 1] as usize],
                );
                let c = cross(
                    [q[0] - p[0], q[1] - p[1], q[2] - p[2]],
                    [r[0] - p[0], r[1] - p[1], r[2] - p[2]],
                );
                for m in 0..3 {
                    area[m] += 0.5 * c[m];
                }
                volume += (p[0] * c[0] + p[1] * c[1] + p[2] * c[2]) / 6.0;
            }
        }
        (area, volume)
    }

    /// Every edge of a closed surface is shared by exactly two elements, in opposite directions.
    fn watertight(s: &SurfaceMesh) -> bool {
        let mut count = std::collections::HashMap::new();
        for e in &s.elements {
            let n = e.n_nodes as usize;
            for k in 0..n {
                *count.entry((e.nodes[k], e.nodes[(k + 1) % n])).or_insert(0) += 1;
            }
        }
        count.iter().all(|(&(a, b), &c)| c == 1 && count.get(&(b, a)) == Some(&1))
    }

    #[test]
    fn closed_generators_are_watertight_outward_and_enclose_their_volume() {
        let pi = std::f64::consts::PI;
        let s = sphere([1.0, 2.0, 3.0], 0.5, 4);
        assert_eq!(s.elements.len(), 20 * 256);
        let (a, v) = closure_and_volume(&s);
        assert!(watertight(&s));
        assert!(a.iter().all(|c| c.abs() < 1e-12), "{a:?}");
        // The inscribed polyhedron's volume converges at second order in the edge length.
        let exact = 4.0 / 3.0 * pi * 0.125;
        let coarse = closure_and_volume(&sphere([0.0; 3], 0.5, 3)).1;
        let (e3, e4) = ((exact - coarse) / exact, (exact - v) / exact);
        assert!(e4 > 0.0 && e4 < 2.5e-3 && (3.5..4.5).contains(&(e3 / e4)), "errors {e3} {e4}");
        assert!(s.x.iter().all(|p| ((p[0] - 1.0).powi(2)
            + (p[1] - 2.0).powi(2)
            + (p[2] - 3.0).powi(2))
        .sqrt()
            - 0.5
            < 1e-14));

        let b = closed_box([0.0, -1.0, 0.5], [2.0, 1.0, 1.0], [4, 3, 2]);
        assert_eq!(b.elements.len(), 2 * (4 * 3 + 3 * 2 + 2 * 4));
        assert!(watertight(&b));
        let (a, v) = closure_and_volume(&b);
        assert!(a.iter().all(|c| c.abs() < 1e-14), "{a:?}");
        assert!((v - 2.0 * 2.0 * 0.5).abs() < 1e-13, "{v}");

        let c = cylinder([0.0, 0.0, 0.0], [0.0, 0.0, 2.0], 0.5, [64, 4], true);
        assert!(watertight(&c));
        let (a, v) = closure_and_volume(&c);
        assert!(a.iter().all(|x| x.abs() < 1e-12), "{a:?}");
        let polygon = 0.5 * 64.0 * 0.25 * (std::f64::consts::TAU / 64.0).sin() * 2.0;
        assert!((v - polygon).abs() < 1e-12, "cylinder volume {v} vs prism {polygon}");
    }

    #[test]
    fn plate_is_open_with_its_stated_normal() {
        let p = plate([0.0; 3], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [4, 2]);
        assert_eq!((p.x.len(), p.elements.len()), (15, 8));
        let (a, _) = closure_and_volume(&p);
        assert!((a[2] - 2.0).abs() < 1e-14 && a[0] == 0.0 && a[1] == 0.0, "{a:?}");
    }
}
