//! Test surfaces and meshes shared by the tracking tests: watertight cube-spheres and boxes with
//! outward winding, open planes, and perturbed box meshes.

use super::Surface;
use crate::mesh::boxmesh::{BoxCells, BoxSpec};
use crate::mesh::{perturb, Mesh};
use interface_protocol::messages::SurfaceElement;
use std::collections::HashMap;

/// A surface at rest from triangles (`phi = 1`).
pub fn surface_of(x: Vec<[f64; 3]>, triangles: &[[u32; 3]]) -> Surface {
    let elements: Vec<SurfaceElement> = triangles
        .iter()
        .map(|t| SurfaceElement { nodes: [t[0], t[1], t[2], 0], n_nodes: 3, ..Default::default() })
        .collect();
    Surface::new(&elements, x, 1).expect("valid test surface")
}

/// The surface of the cube `[-1, 1]^3` cut into `n × n` squares per face (two triangles each),
/// wound outward, nodes shared along the seams; `map` places each point.
fn cube_surface(n: usize, map: impl Fn([f64; 3]) -> [f64; 3]) -> Surface {
    let mut index: HashMap<[usize; 3], u32> = HashMap::new();
    let mut x = Vec::new();
    let mut node = |g: [usize; 3]| {
        *index.entry(g).or_insert_with(|| {
            x.push(map(g.map(|v| 2.0 * v as f64 / n as f64 - 1.0)));
            x.len() as u32 - 1
        })
    };
    let mut triangles = Vec::new();
    for d in 0..3 {
        let (u, v) = ((d + 1) % 3, (d + 2) % 3);
        for side in [0, n] {
            for a in 0..n {
                for b in 0..n {
                    let g = |da: usize, db: usize| {
                        let mut p = [0; 3];
                        p[d] = side;
                        p[u] = a + da;
                        p[v] = b + db;
                        p
                    };
                    let q = [node(g(0, 0)), node(g(1, 0)), node(g(1, 1)), node(g(0, 1))];
                    // e_u × e_v = e_d: counterclockwise in (u, v) faces +d.
                    if side == n {
                        triangles.push([q[0], q[1], q[2]]);
                        triangles.push([q[0], q[2], q[3]]);
                    } else {
                        triangles.push([q[0], q[2], q[1]]);
                        triangles.push([q[0], q[3], q[2]]);
                    }
                }
            }
        }
    }
    surface_of(x, &triangles)
}

/// A closed sphere of `12 n²` triangles (a cube-sphere), wound outward.
pub fn sphere(centre: [f64; 3], radius: f64, n: usize) -> Surface {
    cube_surface(n, |p| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [0, 1, 2].map(|d| centre[d] + radius * p[d] / l)
    })
}

/// The closed box `[lo, hi]` with `n × n` squares per face, wound outward.
pub fn box_surface(lo: [f64; 3], hi: [f64; 3], n: usize) -> Surface {
    cube_surface(n, |p| [0, 1, 2].map(|d| lo[d] + 0.5 * (p[d] + 1.0) * (hi[d] - lo[d])))
}

/// The square `[x0, x1] × [y0, y1]` at height `z` as two triangles.
pub fn plane(x0: f64, x1: f64, y0: f64, y1: f64, z: f64) -> Surface {
    let x = vec![[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]];
    surface_of(x, &[[0, 1, 2], [0, 2, 3]])
}

/// A tet box mesh of the unit cube, its nodes moved by up to `fraction` of their shortest edge.
pub fn cube_mesh(cells: usize, fraction: f64, seed: u64) -> Mesh {
    let spec = BoxSpec::uniform([0.0; 3], [1.0; 3], [cells; 3], BoxCells::Tet);
    let mut raw = spec.raw().expect("valid box");
    if fraction > 0.0 {
        perturb(&mut raw, fraction, seed);
    }
    Mesh::build(raw).expect("valid mesh")
}

/// Whether `p` is inside a closed, consistently wound surface: its winding number (the solid
/// angle the triangles subtend, van Oosterom & Strackee), `1` inside, `0` outside.
pub fn inside_by_winding(s: &Surface, p: [f64; 3]) -> bool {
    let mut w = 0.0;
    for tri in &s.triangles {
        let [a, b, c] = tri.map(|n| {
            let q = s.x_b[n as usize];
            [q[0] - p[0], q[1] - p[1], q[2] - p[2]]
        });
        let l = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
        let (la, lb, lc) = (l(a), l(b), l(c));
        let den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
        w += 2.0 * det.atan2(den);
    }
    w / (4.0 * std::f64::consts::PI) > 0.5
}

use super::adjacency::NodeEdges;
use super::bvh::Bvh;
use super::intersect::{collision, projection, projection_inside, Intersections, SurfaceAt};
use super::predicates::segment_triangle;
use super::status::{flood_fill, step_ratio, swept_nodes, update_sides, NodeStatus, Seed, NO_SIDE};

/// Padding of the test hierarchies.
const PAD: f64 = 1e-12;

fn at<'a>(s: &'a Surface, bvh: &'a Bvh) -> SurfaceAt<'a> {
    SurfaceAt::at_end(s, bvh).unwrap()
}

/// The cut list is sorted, one record per edge, each block's records are its own edges, and
/// each record's point on the edge (α) is its point on the triangle (barycentric coordinates),
/// with the triangle's unit normal.
fn assert_well_formed(mesh: &Mesh, s: &Surface, cuts: &Intersections) {
    assert!(cuts.cuts.windows(2).all(|w| w[0].edge < w[1].edge));
    assert_eq!(cuts.block_offsets.len(), mesh.blocks.len() + 1);
    for b in 0..mesh.blocks.len() {
        let r = mesh.blocks.edges(b);
        assert!(cuts.block(b).iter().all(|c| r.contains(&(c.edge as usize))));
    }
    assert_eq!(*cuts.block_offsets.last().unwrap() as usize, cuts.cuts.len());
    for c in &cuts.cuts {
        assert!((0.0..=1.0).contains(&c.alpha));
        assert!((c.bary.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(c.bary.iter().all(|&b| b >= -1e-15));
        let [i, j] = mesh.edges[c.edge as usize].map(|v| mesh.coords[v as usize]);
        let on_edge = [0, 1, 2].map(|d| i[d] + c.alpha * (j[d] - i[d]));
        let (on_tri, _) = s.point_at(c.triangle as usize, c.bary, s.t_b);
        let occluded_end =
            cuts.occluded[mesh.edges[c.edge as usize][(c.alpha == 1.0) as usize] as usize];
        for d in 0..3 {
            let tol = if occluded_end { 1e-9 } else { 1e-12 };
            assert!(
                (on_edge[d] - on_tri[d]).abs() < tol,
                "edge {}: {on_edge:?} vs {on_tri:?}",
                c.edge
            );
        }
        let t = s.triangles[c.triangle as usize].map(|n| s.x_b[n as usize]);
        assert_eq!(c.normal, super::predicates::unit_normal(t[0], t[1], t[2]));
        assert!((c.normal.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-14);
    }
}

/// Number of distinct points where the segment `p q` crosses the surface (all triangles).
fn crossings(s: &Surface, p: [f64; 3], q: [f64; 3]) -> usize {
    let mut alphas: Vec<f64> = s
        .triangles
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|n| s.x_b[n as usize]);
            segment_triangle(p, q, a, b, c).map(|h| h.alpha)
        })
        .collect();
    alphas.sort_by(f64::total_cmp);
    alphas.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    alphas.len()
}

fn edge_set(c: &Intersections) -> Vec<u32> {
    c.cuts.iter().map(|c| c.edge).collect()
}

/// Both algorithms against a brute-force inside test (winding number) on perturbed tet meshes,
/// for a sphere and a box: every non-occluded node is active exactly when it is outside.
#[test]
fn statuses_agree_with_the_winding_number_for_a_sphere_and_a_box() {
    let bodies = [
        ("sphere", sphere([0.52, 0.47, 0.5], 0.3, 8)),
        ("box", box_surface([0.3, 0.26, 0.34], [0.71, 0.66, 0.72], 3)),
    ];
    for (seed, (name, s)) in bodies.iter().enumerate() {
        let mesh = cube_mesh(12, 0.3, 7 + seed as u64);
        let adj = NodeEdges::build(&mesh);
        let bvh = Bvh::build(s, PAD);
        let truth: Vec<bool> = mesh.coords.iter().map(|&p| inside_by_winding(s, p)).collect();
        let n_inside = truth.iter().filter(|&&b| b).count();
        assert!(n_inside > 50, "{name}: {n_inside} nodes inside");

        let inside = projection_inside(&mesh, &adj, at(s, &bvh));
        assert_eq!(inside, truth, "{name}: Alg. 4.1 inside test");

        let seeds = [
            Seed { point: [0.0, 0.0, 0.0], fluid: true },
            Seed { point: [0.5, 0.47, 0.5], fluid: false },
        ];
        let c42 = collision(&mesh, &adj, at(s, &bvh));
        let c41 = projection(&mesh, &adj, at(s, &bvh));
        for (alg, cuts) in [("4.2", &c42), ("4.1", &c41)] {
            assert_well_formed(&mesh, s, cuts);
            let sides = flood_fill(&mesh, &adj, cuts, &seeds).unwrap();
            let mut checked = 0;
            for i in 0..mesh.n_nodes() {
                if sides.status[i] == NodeStatus::Occluded {
                    continue;
                }
                let active = sides.status[i] == NodeStatus::Active;
                assert_eq!(
                    active, !truth[i],
                    "{name}, Alg. {alg}: node {i} at {:?}",
                    mesh.coords[i]
                );
                checked += 1;
            }
            assert!(checked > mesh.n_nodes() - 5);
        }
        // A resolved closed body: Alg. 4.1's cut edges are Alg. 4.2's, except edges crossing
        // twice near a corner, which only Alg. 4.2 finds.
        let (e41, e42) = (edge_set(&c41), edge_set(&c42));
        assert!(e41.iter().all(|e| e42.binary_search(e).is_ok()), "{name}");
        for c in &c41.cuts {
            assert_eq!(Some(c), c42.find(c.edge), "{name}: same record for edge {}", c.edge);
        }
        // Each edge only Alg. 4.2 cuts has both ends on one side and crosses the surface twice.
        for &e in e42.iter().filter(|e| e41.binary_search(e).is_err()) {
            let [i, j] = mesh.edges[e as usize].map(|v| v as usize);
            assert_eq!(truth[i], truth[j], "{name}: edge {e}");
            assert!(crossings(s, mesh.coords[i], mesh.coords[j]) >= 2, "{name}: edge {e}");
        }
        println!(
            "{name}: {} nodes inside, {} cut edges (4.1), {} (4.2)",
            n_inside,
            e41.len(),
            e42.len()
        );
    }
}

/// A closed plate 0.1 h thick: edges through it cross it twice with both ends outside. Alg. 4.1
/// sees no inside node and misses them all; Alg. 4.2 finds every one.
#[test]
fn thin_closed_plate_doubly_cut_edges_are_found_only_by_collision() {
    let mesh = cube_mesh(10, 0.2, 3);
    let adj = NodeEdges::build(&mesh);
    let h = 0.1;
    let s = box_surface([0.2, 0.25, 0.53], [0.8, 0.75, 0.53 + 0.1 * h], 2);
    let bvh = Bvh::build(&s, PAD);
    // Brute force: edges crossing the plate's surface twice.
    let double: Vec<u32> = (0..mesh.n_edges() as u32)
        .filter(|&e| {
            let [i, j] = mesh.edges[e as usize];
            crossings(&s, mesh.coords[i as usize], mesh.coords[j as usize]) >= 2
        })
        .collect();
    let c41 = projection(&mesh, &adj, at(&s, &bvh));
    let c42 = collision(&mesh, &adj, at(&s, &bvh));
    let (e41, e42) = (edge_set(&c41), edge_set(&c42));
    let found41 = double.iter().filter(|e| e41.binary_search(e).is_ok()).count();
    let found42 = double.iter().filter(|e| e42.binary_search(e).is_ok()).count();
    println!(
        "thin plate: {} doubly cut edges; Alg. 4.1 finds {found41} ({} cut in all), Alg. 4.2 finds {found42} ({} in all)",
        double.len(),
        e41.len(),
        e42.len()
    );
    assert!(double.len() > 30);
    assert_eq!(found41, 0);
    assert_eq!(found42, double.len());
    assert_well_formed(&mesh, &s, &c42);
    // The record is the crossing nearest to node i.
    for &e in &double {
        let [i, j] = mesh.edges[e as usize].map(|v| mesh.coords[v as usize]);
        let first = s
            .triangles
            .iter()
            .filter_map(|t| {
                let [a, b, c] = t.map(|n| s.x_b[n as usize]);
                segment_triangle(i, j, a, b, c).map(|h| h.alpha)
            })
            .fold(f64::INFINITY, f64::min);
        assert_eq!(c42.find(e).unwrap().alpha, first);
    }
    // The fluid on both faces of the plate is one region around its rim, with no node inside.
    let sides = flood_fill(&mesh, &adj, &c42, &[Seed { point: [0.0; 3], fluid: true }]).unwrap();
    assert!(sides.status.iter().all(|&s| s == NodeStatus::Active));
}

/// The plane `z = zp` over the whole mesh as one quad element with the given phi at its corners.
fn plate_elements(phis: &[[f64; 4]], zp: f64) -> Surface {
    use interface_protocol::messages::SurfaceElement;
    let x = vec![[-0.2, -0.2, zp], [1.2, -0.2, zp], [1.2, 1.2, zp], [-0.2, 1.2, zp]];
    let elements: Vec<SurfaceElement> = phis
        .iter()
        .map(|&phi| SurfaceElement { nodes: [0, 1, 2, 3], n_nodes: 4, phi, ..Default::default() })
        .collect();
    Surface::new(&elements, x, 1).unwrap()
}

/// Crack awareness (thesis §4.3.3, DESIGN §3): the cracked element as its two phantom elements,
/// phi = f = x - x_c on one and -f on the other. Alone, each cuts exactly the edges crossing its
/// real part; together they cut every crossing edge, as the uncracked plate (phi = 1) does.
#[test]
fn phantom_elements_cut_only_through_their_real_part_and_never_leak() {
    let mesh = cube_mesh(10, 0.2, 11);
    let adj = NodeEdges::build(&mesh);
    let (zp, xc) = (0.53, 0.437);
    // phi = x - xc at the corners x = -0.2, 1.2, 1.2, -0.2.
    let f = [-0.2 - xc, 1.2 - xc, 1.2 - xc, -0.2 - xc];
    let minus = f.map(|v| -v);
    let run = |phis: &[[f64; 4]]| {
        let s = plate_elements(phis, zp);
        let bvh = Bvh::build(&s, PAD);
        let c = collision(&mesh, &adj, at(&s, &bvh));
        assert_well_formed(&mesh, &s, &c);
        c
    };
    // Edges crossing the plane, with the x of the crossing.
    let crossing: Vec<(u32, f64)> = mesh
        .edges
        .iter()
        .enumerate()
        .filter_map(|(e, &[i, j])| {
            let (p, q) = (mesh.coords[i as usize], mesh.coords[j as usize]);
            ((p[2] - zp) * (q[2] - zp) < 0.0).then(|| {
                let a = (zp - p[2]) / (q[2] - p[2]);
                (e as u32, p[0] + a * (q[0] - p[0]))
            })
        })
        .collect();
    let all: Vec<u32> = crossing.iter().map(|c| c.0).collect();
    assert!(all.len() > 200);
    assert_eq!(edge_set(&run(&[[1.0; 4]])), all, "uncracked plate");
    assert_eq!(edge_set(&run(&[f, minus])), all, "both phantom elements");
    for (phi, real) in [(f, 1.0), (minus, -1.0)] {
        let cut = edge_set(&run(&[phi]));
        let mut n = 0;
        for &(e, x) in &crossing {
            if ((x - xc) * real).abs() < 1e-9 {
                continue;
            }
            let expect = (x - xc) * real > 0.0;
            assert_eq!(cut.binary_search(&e).is_ok(), expect, "edge {e} crossing at x = {x}");
            n += expect as usize;
        }
        assert!(n > 50 && n < all.len() - 50, "{n} edges through the real part");
    }
}

/// A plane moving up by less than a cell: exactly the nodes between its two positions are
/// swept, and they move from the side above to the side below.
#[test]
fn swept_nodes_of_a_translated_plane_change_side() {
    let mesh = cube_mesh(8, 0.25, 5);
    let adj = NodeEdges::build(&mesh);
    let (z0, z1, dt) = (0.41, 0.41 + 0.09, 0.01);
    let mut s = plane(-0.5, 1.5, -0.5, 1.5, z0);
    let mut bvh = Bvh::build(&s, PAD);
    let cuts0 = collision(&mesh, &adj, at(&s, &bvh));
    let seeds = [
        Seed { point: [0.5, 0.5, 0.0], fluid: true },
        Seed { point: [0.5, 0.5, 1.0], fluid: true },
    ];
    let sides0 = flood_fill(&mesh, &adj, &cuts0, &seeds).unwrap();
    let below = sides0.side[(0..mesh.n_nodes()).find(|&i| mesh.coords[i][2] == 0.0).unwrap()];
    let above = sides0.side[(0..mesh.n_nodes()).find(|&i| mesh.coords[i][2] == 1.0).unwrap()];
    assert_ne!(below, above);
    for i in 0..mesh.n_nodes() {
        assert_eq!(sides0.side[i], if mesh.coords[i][2] < z0 { below } else { above });
        assert_eq!(sides0.status[i], NodeStatus::Active);
    }
    let x1: Vec<[f64; 3]> = s.x_b.iter().map(|p| [p[0], p[1], z1]).collect();
    let v = vec![[0.0, 0.0, (z1 - z0) / dt]; 4];
    s.advance(dt, &x1, &v);
    bvh.refit(&s).unwrap();
    bvh.validate().unwrap();
    let cuts1 = collision(&mesh, &adj, at(&s, &bvh));
    let swept = swept_nodes(&mesh, &s, &bvh);
    let expect: Vec<u32> = (0..mesh.n_nodes() as u32)
        .filter(|&i| (z0..z1).contains(&mesh.coords[i as usize][2]))
        .collect();
    assert!(expect.len() > 10, "{} nodes between the planes", expect.len());
    assert_eq!(swept, expect);
    let (sides1, changes) = update_sides(&mesh, &adj, &sides0, &cuts1, &swept);
    assert_eq!(changes.iter().map(|c| c.node).collect::<Vec<_>>(), expect);
    for c in &changes {
        assert_eq!((c.old_side, c.new_side), (above, below));
        assert_eq!((c.old_status, c.new_status), (NodeStatus::Active, NodeStatus::Active));
    }
    assert!(sides1.side.iter().all(|&s| s != NO_SIDE));
    // The same sides as a fresh flood fill at the new position.
    let fresh = flood_fill(&mesh, &adj, &cuts1, &seeds).unwrap();
    assert_eq!(fresh.side, sides1.side);
}

/// A sphere moving through the mesh, a fraction of a cell per step: after each step the sides
/// updated from the swept nodes give every node the status a brute-force inside test gives, the
/// same as a fresh flood fill; only swept or occluded nodes change.
#[test]
fn a_moving_sphere_keeps_statuses_right_through_swept_nodes() {
    let mesh = cube_mesh(12, 0.3, 21);
    let adj = NodeEdges::build(&mesh);
    let mut s = sphere([0.4, 0.5, 0.48], 0.27, 8);
    let rest = s.x_b.clone();
    let mut bvh = Bvh::build(&s, PAD);
    let seeds =
        [Seed { point: [0.0; 3], fluid: true }, Seed { point: [0.4, 0.5, 0.48], fluid: false }];
    let mut sides = flood_fill(&mesh, &adj, &collision(&mesh, &adj, at(&s, &bvh)), &seeds).unwrap();
    let mut changed = 0;
    for step in 1..=4 {
        let (shift, t) = (0.05 * step as f64, 0.01 * step as f64);
        let x: Vec<[f64; 3]> =
            rest.iter().map(|p| [p[0] + shift, p[1], p[2] + 0.3 * shift]).collect();
        s.advance(t, &x, &vec![[5.0, 0.0, 1.5]; x.len()]);
        bvh.refit(&s).unwrap();
        let cuts = collision(&mesh, &adj, at(&s, &bvh));
        let swept = swept_nodes(&mesh, &s, &bvh);
        let (new, changes) = update_sides(&mesh, &adj, &sides, &cuts, &swept);
        for c in &changes {
            let i = c.node as usize;
            assert!(
                swept.binary_search(&c.node).is_ok()
                    || cuts.occluded[i]
                    || sides.status[i] == NodeStatus::Occluded
            );
        }
        let fresh = flood_fill(&mesh, &adj, &cuts, &seeds).unwrap();
        assert_eq!(new.status, fresh.status, "step {step}");
        for i in 0..mesh.n_nodes() {
            if new.status[i] != NodeStatus::Occluded {
                let active = new.status[i] == NodeStatus::Active;
                assert_eq!(active, !inside_by_winding(&s, mesh.coords[i]), "step {step}, node {i}");
            }
        }
        changed += changes.len();
        sides = new;
    }
    println!("moving sphere: {changed} nodes changed side or status in 4 steps");
    assert!(changed > 40, "{changed} nodes changed side");
}

/// §4.4: on a uniform tet grid the shortest edge a horizontal plane cuts is a vertical one,
/// of length h, so a move of 0.09 over h = 0.125 gives 0.72.
#[test]
fn step_ratio_compares_the_move_with_the_cut_edges() {
    let mesh = cube_mesh(8, 0.0, 0);
    let adj = NodeEdges::build(&mesh);
    let mut s = plane(-0.5, 1.5, -0.5, 1.5, 0.41);
    let x1: Vec<[f64; 3]> = s.x_b.iter().map(|p| [p[0], p[1], 0.5]).collect();
    s.advance(0.01, &x1, &[[0.0; 3]; 4]);
    let bvh = Bvh::build(&s, PAD);
    let cuts = collision(&mesh, &adj, at(&s, &bvh));
    let r = step_ratio(&mesh, &s, &cuts);
    assert!((r - 0.09 / 0.125).abs() < 1e-12, "{r}");
}

/// Seeds that contradict each other or sit on the surface are named, as are mismatched views.
#[test]
fn bad_seeds_are_named() {
    use super::intersect::SurfaceAtError;
    use super::status::StatusError;
    let mesh = cube_mesh(6, 0.0, 0);
    let adj = NodeEdges::build(&mesh);
    let s = plane(-0.5, 1.5, -0.5, 1.5, 0.5);
    let bvh = Bvh::build(&s, PAD);
    let cuts = collision(&mesh, &adj, at(&s, &bvh));
    let seed = |z: f64, fluid| Seed { point: [0.3, 0.3, z], fluid };
    let err = flood_fill(&mesh, &adj, &cuts, &[seed(0.1, true), seed(0.2, false)]).unwrap_err();
    assert!(matches!(err, StatusError::Conflict { first: 0, second: 1, .. }));
    let err = flood_fill(&mesh, &adj, &cuts, &[seed(0.5, true)]).unwrap_err();
    assert!(matches!(err, StatusError::OccludedSeed { seed: 0, .. }), "{err}");
    assert_eq!(flood_fill(&mesh, &adj, &cuts, &[]).unwrap_err(), StatusError::NoSeed);
    let short = [[0.0; 3]; 3];
    let err = SurfaceAt::new(&s, &short, &bvh).err();
    assert_eq!(err, Some(SurfaceAtError::Positions { expected: 4, got: 3 }));
    let other = Bvh::build(&sphere([0.0; 3], 1.0, 1), 0.0);
    assert!(matches!(SurfaceAt::at_end(&s, &other), Err(SurfaceAtError::Bvh(_))));
    // Nodes on the plane are occluded and every edge touching them is cut.
    let mask = cuts.cut_mask(mesh.n_edges());
    for (e, &[i, j]) in mesh.edges.iter().enumerate() {
        if cuts.occluded[i as usize] || cuts.occluded[j as usize] {
            assert!(mask[e]);
        }
    }
    assert_eq!(cuts.occluded.iter().filter(|&&o| o).count(), 49);
}

/// Time of the tracking on a ~200k-node tet cube with a ~10k-triangle sphere (release build:
/// `cargo test --release -p fluid-solver --lib embedded::tests::tracking_time -- --ignored --nocapture`).
#[test]
#[ignore]
fn tracking_time() {
    use std::time::Instant;
    let mesh = cube_mesh(57, 0.2, 1);
    let t = Instant::now();
    let adj = NodeEdges::build(&mesh);
    let t_adj = t.elapsed();
    let s = sphere([0.5; 3], 0.3, 29);
    let t = Instant::now();
    let mut bvh = Bvh::build(&s, PAD);
    let t_build = t.elapsed();
    let t = Instant::now();
    bvh.refit(&s).unwrap();
    let t_refit = t.elapsed();
    let t = Instant::now();
    let c42 = collision(&mesh, &adj, at(&s, &bvh));
    let t42 = t.elapsed();
    let t = Instant::now();
    let c41 = projection(&mesh, &adj, at(&s, &bvh));
    let t41 = t.elapsed();
    let t = Instant::now();
    let seeds = [Seed { point: [0.0; 3], fluid: true }];
    let _ = flood_fill(&mesh, &adj, &c42, &seeds).unwrap();
    let t_fill = t.elapsed();
    let t = Instant::now();
    let swept = swept_nodes(&mesh, &s, &bvh);
    let t_swept = t.elapsed();
    println!(
        "{} nodes, {} edges, {} triangles, {} threads: adjacency {:?}, bvh build {:?}, refit {:?}, Alg. 4.2 {:?} ({} cuts), Alg. 4.1 {:?} ({} cuts), flood fill {:?}, swept nodes {:?} ({})",
        mesh.n_nodes(),
        mesh.n_edges(),
        s.triangles.len(),
        rayon::current_num_threads(),
        t_adj,
        t_build,
        t_refit,
        t42,
        c42.cuts.len(),
        t41,
        c41.cuts.len(),
        t_fill,
        t_swept,
        swept.len()
    );
}
