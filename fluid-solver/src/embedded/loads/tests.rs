//! The loads against thesis §5.3.4 (the manufactured pressure `p = sin(x + y)` on a square
//! ribbon) and the closed-surface identities (zero resultant of a constant pressure).

use super::*;
use crate::embedded::test_cuts::brute_force_cuts;
use crate::mesh::boxmesh::{BoxCells, BoxSpec};
use crate::mesh::geometry::{add, cross, norm, scale, sub};
use crate::mesh::perturb;
use interface_protocol::messages::SurfaceElement;

mod shells;

fn surface(x: Vec<[f64; 3]>, elements: &[[u32; 4]]) -> Surface {
    let e: Vec<SurfaceElement> = elements
        .iter()
        .map(|n| SurfaceElement {
            nodes: *n,
            n_nodes: if n[3] == u32::MAX { 3 } else { 4 },
            ..Default::default()
        })
        .collect();
    let e: Vec<SurfaceElement> = e
        .into_iter()
        .map(|mut s| {
            if s.n_nodes == 3 {
                s.nodes[3] = 0;
            }
            s
        })
        .collect();
    Surface::new(&e, x, 0).unwrap()
}

/// The square ribbon of thesis §5.3.4: the square `[-1, 1]²` extruded over `[z0, z1]`, wound so
/// that `n_E` points out of the square.
fn ribbon(z0: f64, z1: f64) -> Surface {
    let p = [[1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]];
    let mut x = Vec::new();
    for z in [z0, z1] {
        x.extend(p.iter().map(|q| [q[0], q[1], z]));
    }
    let quads: Vec<[u32; 4]> =
        (0..4u32).map(|k| [k, (k + 1) % 4, (k + 1) % 4 + 4, k + 4]).collect();
    surface(x, &quads)
}

/// Nodes reachable from node `seed` through edges the surface does not cut.
fn flood_fill(mesh: &Mesh, cuts: &[CutEdge], seed: usize) -> Vec<bool> {
    let mut adj = vec![Vec::new(); mesh.n_nodes()];
    let mut k = 0;
    for (e, &[i, j]) in mesh.edges.iter().enumerate() {
        while k < cuts.len() && (cuts[k].edge as usize) < e {
            k += 1;
        }
        if k < cuts.len() && cuts[k].edge as usize == e {
            continue;
        }
        adj[i as usize].push(j as usize);
        adj[j as usize].push(i as usize);
    }
    let mut seen = vec![false; mesh.n_nodes()];
    let mut stack = vec![seed];
    seen[seed] = true;
    while let Some(i) = stack.pop() {
        for &j in &adj[i] {
            if !seen[j] {
                seen[j] = true;
                stack.push(j);
            }
        }
    }
    seen
}

/// `p*` on each side: `p(X)` at the intersection point `X` on the fluid side, `NaN` elsewhere.
fn prescribe(
    mesh: &Mesh,
    cuts: &[CutEdge],
    fluid: &[bool],
    p: impl Fn([f64; 3]) -> f64,
) -> Vec<[f64; 2]> {
    cuts.iter()
        .map(|c| {
            let [i, j] = mesh.edges[c.edge as usize];
            let (xi, xj) = (mesh.coords[i as usize], mesh.coords[j as usize]);
            let x = add(xi, scale(sub(xj, xi), c.alpha));
            [i, j].map(|n| if fluid[n as usize] { p(x) } else { f64::NAN })
        })
        .collect()
}

struct Loaded {
    force: [f64; 3],
    /// `Σ (x_node - centre) × f_node`.
    moment: [f64; 3],
}

fn load(
    algorithm: LoadAlgorithm,
    mesh: &Mesh,
    s: &Surface,
    cuts: &[CutEdge],
    outer: &[bool],
    p_star: &[[f64; 2]],
    centre: [f64; 3],
) -> Loaded {
    let side: Vec<u32> = outer.iter().map(|&o| o as u32).collect();
    let adjacency = &NodeEdges::build(mesh);
    let view = LoadView { mesh, adjacency, surface: s, t: 0.0, side: &side, cuts, p_star };
    let mut out = vec![[0.0; 3]; s.n_nodes()];
    nodal_loads(algorithm, &view, &mut out).unwrap();
    let mut force = [0.0; 3];
    let mut moment = [0.0; 3];
    for (f, x) in out.iter().zip(&s.x_b) {
        force = add(force, *f);
        moment = add(moment, cross(sub(*x, centre), *f));
    }
    Loaded { force, moment }
}

fn sci(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(" ")
}

/// Least-squares slope of `ln e` against `ln h`.
fn fitted_order(h: &[f64], e: &[f64]) -> f64 {
    let n = h.len() as f64;
    let (x, y): (Vec<f64>, Vec<f64>) = h.iter().zip(e).map(|(a, b)| (a.ln(), b.ln())).unzip();
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// Relative error of the ribbon resultant on a one-cell-thick mesh of `[-2, 2]²` with `n` cells
/// per side, fluid outside the ribbon (`outside`) or inside. The force on the structure is
/// `∓ dz (2(1 - cos 2), 2(1 - cos 2), 0)`: the outer fluid pushes inwards, `-∮ p n_out` (thesis
/// Eq. 5.55 is `+∮ p n_out`, the push of the fluid inside).
fn ribbon_error(algorithm: LoadAlgorithm, n: usize, shape: BoxCells, jitter: f64) -> f64 {
    let h = 4.0 / n as f64;
    let spec = BoxSpec::uniform([-2.0, -2.0, 0.0], [2.0, 2.0, h], [n, n, 1], shape);
    let mut raw = spec.raw().unwrap();
    if jitter > 0.0 {
        perturb(&mut raw, jitter, 7 + n as u64);
    }
    let mesh = Mesh::build(raw).unwrap();
    let s = ribbon(-1.0, h + 1.0);
    let cuts = brute_force_cuts(&mesh, &s, 0.0);
    let corner = (0..mesh.n_nodes()).find(|&k| mesh.coords[k][0] == -2.0).unwrap();
    let outer = flood_fill(&mesh, &cuts, corner);
    let p_star = prescribe(&mesh, &cuts, &outer, |x| (x[0] + x[1]).sin());
    let f = load(algorithm, &mesh, &s, &cuts, &outer, &p_star, [0.0; 3]).force;
    let exact = -2.0 * (1.0 - 2f64.cos()) * h;
    norm(sub(f, [exact, exact, 0.0])) / (exact.abs() * 2f64.sqrt())
}

/// The ribbon errors on meshes `ns`, printed with their fitted order and compared with the
/// committed table `ribbon_errors.json` (to 1%: the table holds four digits).
fn ribbon_study(algorithm: LoadAlgorithm, table: &str, shape: BoxCells, jitter: f64) -> f64 {
    let reference: serde_json::Value =
        serde_json::from_str(include_str!("ribbon_errors.json")).unwrap();
    let column = |key: &str| -> Vec<f64> {
        reference[table][key].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect()
    };
    let ns: Vec<usize> = column("n").iter().map(|&n| n as usize).collect();
    let key = match algorithm {
        LoadAlgorithm::Facets => "facets",
        LoadAlgorithm::Reconstructed => "reconstructed",
    };
    let h: Vec<f64> = ns.iter().map(|&n| 4.0 / n as f64).collect();
    let e: Vec<f64> = ns.iter().map(|&n| ribbon_error(algorithm, n, shape, jitter)).collect();
    let order = fitted_order(&h, &e);
    println!(
        "{algorithm:?} {shape:?} jitter {jitter}: n {ns:?} errors {} order {order:.2}",
        sci(&e)
    );
    for (got, want) in e.iter().zip(column(key)) {
        assert!((got - want).abs() <= 0.01 * want, "{algorithm:?} {table}: {got:e} vs {want:e}");
    }
    order
}

/// Thesis §5.3.4 ideal case: uniform hexes with the ribbon on dual facets (`n ≡ 2 mod 4`
/// puts x, y = ±1 half-way between nodes): both algorithms second order (measured 2.01 for
/// Alg. 5.4, 1.98 for Alg. 5.3; the thesis finds 5.4 the more accurate here, as we do).
#[test]
fn ribbon_on_dual_facets_is_second_order() {
    for algorithm in [LoadAlgorithm::Facets, LoadAlgorithm::Reconstructed] {
        let order = ribbon_study(algorithm, "hex_on_dual_facets", BoxCells::Hex, 0.0);
        assert!(order >= 1.8, "{algorithm:?}: order {order}");
    }
}

/// Thesis §5.3.4 realistic case: arbitrary triangles (tets of a one-cell-thick mesh whose nodes
/// move by 20% of the local edge length): Alg. 5.3 second order (measured 2.86), Alg. 5.4 at
/// least first (measured 1.46, irregular as in the thesis' Fig. 5.23).
#[test]
fn ribbon_on_arbitrary_tets() {
    let table = "tet_perturbed_20_percent";
    let o3 = ribbon_study(LoadAlgorithm::Reconstructed, table, BoxCells::Tet, 0.2);
    let o4 = ribbon_study(LoadAlgorithm::Facets, table, BoxCells::Tet, 0.2);
    assert!(o3 >= 1.8, "Alg. 5.3: order {o3}");
    assert!(o4 >= 1.0, "Alg. 5.4: order {o4}");
}

/// A fluid inside the ribbon pushes it outwards: the opposite resultant (thesis Eq. 5.55's sign),
/// within the discretisation error of this coarse mesh (2.1% for Alg. 5.3 at n = 10).
#[test]
fn fluid_inside_pushes_outwards() {
    let n = 10;
    let h = 0.4;
    let mesh = Mesh::build(
        BoxSpec::uniform([-2.0, -2.0, 0.0], [2.0, 2.0, h], [n, n, 1], BoxCells::Hex).raw().unwrap(),
    )
    .unwrap();
    let s = ribbon(-1.0, h + 1.0);
    let cuts = brute_force_cuts(&mesh, &s, 0.0);
    let corner = (0..mesh.n_nodes()).find(|&k| mesh.coords[k][0] == -2.0).unwrap();
    let outer = flood_fill(&mesh, &cuts, corner);
    let inner: Vec<bool> = outer.iter().map(|o| !o).collect();
    let p_star = prescribe(&mesh, &cuts, &inner, |x| (x[0] + x[1]).sin());
    let exact = 2.0 * (1.0 - 2f64.cos()) * h;
    for algorithm in [LoadAlgorithm::Facets, LoadAlgorithm::Reconstructed] {
        let f = load(algorithm, &mesh, &s, &cuts, &outer, &p_star, [0.0; 3]).force;
        assert!(
            (f[0] - exact).abs() < 0.03 * exact && (f[1] - exact).abs() < 0.03 * exact,
            "{algorithm:?}: {f:?} against {exact}"
        );
    }
}

/// Rotation by `angle` about the unit axis `a`.
fn rotate(a: [f64; 3], angle: f64, v: [f64; 3]) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    let k = scale(a, 1.0 / norm(a));
    let kv = cross(k, v);
    let kdv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    add(add(scale(v, c), scale(kv, s)), scale(k, kdv * (1.0 - c)))
}

/// An icosphere of radius `r` about the origin with `levels` refinements, as triangles.
fn icosphere(levels: usize, r: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let s = crate::embedded::generate::sphere([0.0; 3], r, levels as u32);
    let tris = s.elements.iter().map(|e| [e.nodes[0], e.nodes[1], e.nodes[2]]).collect();
    (s.x, tris)
}

/// A cube of side `a` centred at the origin as 6 outward quads.
fn cube_surface(a: f64) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let h = 0.5 * a;
    let x: Vec<[f64; 3]> = (0..8)
        .map(|k| [k & 1, (k >> 1) & 1, (k >> 2) & 1].map(|b| if b == 1 { h } else { -h }))
        .collect();
    let quads =
        vec![[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    (x, quads)
}

/// Residuals of a uniform pressure on a closed surface (all exactly zero), relative to `p A`
/// for forces and `p A R` for moments.
struct ClosedResiduals {
    /// Net nodal force of Alg. 5.3 and of Alg. 5.4.
    force: [f64; 2],
    /// Net nodal moment about the centre of Alg. 5.3 and of Alg. 5.4.
    moment: [f64; 2],
    /// Moment of Alg. 5.3's load on the reconstructed interface itself (at its Gauss points,
    /// before the projection onto the structure).
    reconstructed_moment: f64,
}

/// Uniform pressure outside a closed surface on mesh `n` of `[-1, 1]³`.
fn closed_surface_residuals(
    s: &Surface,
    centre: [f64; 3],
    n: usize,
    shape: BoxCells,
    jitter: f64,
) -> ClosedResiduals {
    let mut raw = BoxSpec::uniform([-1.0; 3], [1.0; 3], [n; 3], shape).raw().unwrap();
    if jitter > 0.0 {
        perturb(&mut raw, jitter, 3);
    }
    let mesh = Mesh::build(raw).unwrap();
    let cuts = brute_force_cuts(&mesh, s, 0.0);
    let corner = (0..mesh.n_nodes()).find(|&k| mesh.coords[k] == [-1.0; 3]).unwrap();
    let outer = flood_fill(&mesh, &cuts, corner);
    assert!(outer.iter().any(|o| !o), "the surface encloses nodes");
    let p = 1e5;
    let p_star = prescribe(&mesh, &cuts, &outer, |_| p);
    let (mut area, mut radius) = (0.0, 0.0f64);
    for t in 0..s.triangles.len() {
        let (x, _) = s.triangle_at(t, 0.0);
        area += 0.5 * norm(cross(sub(x[1], x[0]), sub(x[2], x[0])));
        for y in x {
            radius = radius.max(norm(sub(y, centre)));
        }
    }
    let [l3, l4] = [LoadAlgorithm::Reconstructed, LoadAlgorithm::Facets]
        .map(|a| load(a, &mesh, s, &cuts, &outer, &p_star, centre));
    let side: Vec<u32> = outer.iter().map(|&o| o as u32).collect();
    let adjacency = &NodeEdges::build(&mesh);
    let view = LoadView {
        mesh: &mesh,
        adjacency,
        surface: s,
        t: 0.0,
        side: &side,
        cuts: &cuts,
        p_star: &p_star,
    };
    let mut m = [0.0; 3];
    reconstructed::vertex_loads(&view, |x, f, _, _| m = add(m, cross(sub(x, centre), f)));
    ClosedResiduals {
        force: [norm(l3.force) / (p * area), norm(l4.force) / (p * area)],
        moment: [l3.moment, l4.moment].map(|m| norm(m) / (p * area * radius)),
        reconstructed_moment: norm(m) / (p * area * radius),
    }
}

/// The closed surfaces of issue 10: a sphere centred on a grid node and one rotated and off the
/// grid, a cube off the grid with its faces along the grid planes and one rotated.
fn closed_surfaces() -> Vec<(&'static str, Surface, [f64; 3])> {
    let axis = [1.0, 2.0, 3.0];
    let tri = |t: Vec<[u32; 3]>| -> Vec<[u32; 4]> {
        t.iter().map(|t| [t[0], t[1], t[2], u32::MAX]).collect()
    };
    let (x, t) = icosphere(2, 0.62);
    let sphere = surface(x, &tri(t));
    let c_sphere = [0.031, -0.023, 0.047];
    let (x, t) = icosphere(2, 0.62);
    let x = x.into_iter().map(|p| add(rotate(axis, 0.4, p), c_sphere)).collect();
    let rotated_sphere = surface(x, &tri(t));
    let c_cube = [-0.043, 0.029, 0.017];
    let (x, q) = cube_surface(0.93);
    let cube = surface(x.iter().map(|p| add(*p, c_cube)).collect(), &q);
    let x = x.into_iter().map(|p| add(rotate(axis, 0.7, p), c_cube)).collect();
    let rotated_cube = surface(x, &q);
    vec![
        ("sphere", sphere, [0.0; 3]),
        ("rotated off-grid sphere", rotated_sphere, c_sphere),
        ("off-grid cube", cube, c_cube),
        ("rotated off-grid cube", rotated_cube, c_cube),
    ]
}

/// A constant pressure on closed surfaces, on uniform hexes and perturbed tets: zero net force to
/// round-off with both algorithms, and zero moment with Alg. 5.3, both on the (closed)
/// reconstructed interface and at the structure nodes (its vertex forces reach the structure at
/// the intersection points themselves, Eq. 5.18).
#[test]
fn constant_pressure_on_closed_surfaces_gives_no_net_force() {
    for (name, s, c) in closed_surfaces() {
        for (shape, jitter) in [(BoxCells::Hex, 0.0), (BoxCells::Tet, 0.2)] {
            let r = closed_surface_residuals(&s, c, 12, shape, jitter);
            println!(
                "{name} {shape:?}: force {}, nodal moment {}, reconstructed moment {:.2e}",
                sci(&r.force),
                sci(&r.moment),
                r.reconstructed_moment
            );
            assert!(r.force.iter().all(|&f| f < 1e-14), "{name} {shape:?}: {:?}", r.force);
            assert!(r.reconstructed_moment < 1e-14, "{name} {shape:?}");
            assert!(r.moment[0] < 1e-12, "{name} {shape:?}: Alg. 5.3 moment {:e}", r.moment[0]);
        }
    }
}

/// The nodal moment of a constant pressure on the closed surfaces over three perturbed tet
/// meshes (exact: zero): Alg. 5.3 zero to round-off on each (measured at most 1.4e-16 of
/// `p A R`); Alg. 5.4 applies `p ν` at the intersection points, which the dual facets do not
/// centre, so its moment is a discretisation error, irregular in `h` (measured at n = 8, 12, 16:
/// sphere 3.0e-3 to 2.8e-4, fitted order 3.2; rotated sphere 4.3e-3 to 1.6e-3, order 1.5; off-grid
/// cube 1.1e-2 to 7.7e-3, order 0.6; rotated cube 1.1e-3 to 4.3e-4, order 1.35).
#[test]
fn constant_pressure_moment_on_closed_surfaces() {
    let ns = [8, 12, 16];
    let mut failed = Vec::new();
    for (name, s, c) in closed_surfaces() {
        let h: Vec<f64> = ns.iter().map(|&n| 2.0 / n as f64).collect();
        let r: Vec<ClosedResiduals> =
            ns.iter().map(|&n| closed_surface_residuals(&s, c, n, BoxCells::Tet, 0.2)).collect();
        let m3: Vec<f64> = r.iter().map(|x| x.moment[0]).collect();
        let m4: Vec<f64> = r.iter().map(|x| x.moment[1]).collect();
        let o4 = fitted_order(&h, &m4);
        println!("{name}: moment 5.3 {}; 5.4 {} order {o4:.2}", sci(&m3), sci(&m4));
        for x in &r {
            assert!(x.force.iter().all(|&f| f < 1e-14) && x.reconstructed_moment < 1e-14);
        }
        if !(m3.iter().all(|&m| m < 1e-12) && m4.iter().all(|&m| m < 1.5e-2) && m4[2] < m4[0]) {
            failed.push((name, m3, m4));
        }
    }
    assert!(failed.is_empty(), "moments (Alg. 5.3, Alg. 5.4): {failed:?}");
}

/// An ambiguous hex face: a thin ellipsoid along the diagonal of the face z = 0 of unit hexes
/// holds two opposite corners of it and not the other two, so the face has four cut edges and the
/// cells above and below must pair them alike. A constant pressure gives no net force.
#[test]
fn ambiguous_hex_face_is_closed_alike_from_both_cells() {
    let mut raw = BoxSpec::uniform([-1.0, -1.0, -1.0], [2.0, 2.0, 1.0], [3, 3, 2], BoxCells::Hex)
        .raw()
        .unwrap();
    // The cell above the face numbered a quarter turn about z from the one below, so that a rule
    // reading the face from its local first node would pair its edges differently in the two.
    let above = raw
        .cells
        .iter()
        .position(|c| {
            let m = c.nodes().iter().fold([0.0; 3], |s, &v| add(s, raw.coords[v as usize]));
            norm(sub(scale(m, 0.125), [0.5, 0.5, 0.5])) < 1e-12
        })
        .unwrap();
    let h = raw.cells[above].nodes;
    raw.cells[above].nodes[..8].copy_from_slice(&[h[1], h[2], h[3], h[0], h[5], h[6], h[7], h[4]]);
    let mesh = Mesh::build(raw).unwrap();
    let (x, t) = icosphere(3, 1.0);
    let axes = [[0.9 / 2f64.sqrt(), -0.9 / 2f64.sqrt(), 0.0], [0.2, 0.2, 0.0], [0.0, 0.0, 0.3]];
    let x = x
        .into_iter()
        .map(|p| {
            let mut y = [0.5, 0.5, 0.013];
            for (k, a) in axes.iter().enumerate() {
                y = add(y, scale(*a, p[k]));
            }
            y
        })
        .collect();
    let t: Vec<[u32; 4]> = t.iter().map(|t| [t[0], t[1], t[2], u32::MAX]).collect();
    let s = surface(x, &t);
    let cuts = brute_force_cuts(&mesh, &s, 0.0);
    let corner = (0..mesh.n_nodes()).find(|&k| mesh.coords[k] == [-1.0; 3]).unwrap();
    let outer = flood_fill(&mesh, &cuts, corner);
    let mut inner: Vec<[f64; 3]> =
        (0..mesh.n_nodes()).filter(|&k| !outer[k]).map(|k| mesh.coords[k]).collect();
    inner.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(inner, vec![[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]], "two opposite corners inside");
    let p_star = prescribe(&mesh, &cuts, &outer, |_| 1.0);
    let f = load(LoadAlgorithm::Reconstructed, &mesh, &s, &cuts, &outer, &p_star, [0.0; 3]);
    assert!(norm(f.force) < 1e-14, "{:?}", f.force);
}

/// Wrong buffer lengths and cut edges outside the mesh are named errors.
#[test]
fn bad_inputs_are_named() {
    let mesh = Mesh::build(
        BoxSpec::uniform([-2.0, -2.0, 0.0], [2.0, 2.0, 1.0], [2, 2, 1], BoxCells::Hex)
            .raw()
            .unwrap(),
    )
    .unwrap();
    let s = ribbon(-1.0, 2.0);
    let cuts = brute_force_cuts(&mesh, &s, 0.0);
    let p = vec![[1.0, f64::NAN]; cuts.len()];
    let side = vec![0u32; mesh.n_nodes()];
    let adjacency = &NodeEdges::build(&mesh);
    let view = LoadView {
        mesh: &mesh,
        adjacency,
        surface: &s,
        t: 0.0,
        side: &side,
        cuts: &cuts,
        p_star: &p,
    };
    let mut out = vec![[0.0; 3]; 3];
    let err = nodal_loads(LoadAlgorithm::Facets, &view, &mut out).unwrap_err();
    assert_eq!(err, LoadError::Length { what: "the loads buffer", got: 3, expected: 8 });
    let bad = [CutEdge { edge: 999, ..cuts[0] }];
    let view = LoadView { cuts: &bad, p_star: &p[..1], ..view };
    let mut out = vec![[0.0; 3]; 8];
    let err = nodal_loads(LoadAlgorithm::Reconstructed, &view, &mut out).unwrap_err();
    assert!(matches!(err, LoadError::BadCut { index: 0, edge: 999, .. }), "{err}");
}

/// Alg. 5.3 over the cells around the cut edges equals the pass over every cell of the mesh
/// bitwise (same cells, same order), for a sphere moving through perturbed tets and hexes and for
/// a shell wet on both sides (whose rim cells close no cycle), while visiting a small part of
/// the mesh.
#[test]
fn cells_around_the_cuts_give_the_loads_of_all_cells() {
    let shell = || {
        let x = [[-3.0, -3.0, 0.11], [3.0, -3.0, -0.2], [3.0, 3.0, 0.3], [-3.0, 3.0, 0.05]];
        surface(x.to_vec(), &[[0, 1, 2, 3]])
    };
    for (shape, jitter) in [(BoxCells::Tet, 0.2), (BoxCells::Hex, 0.0)] {
        let mut raw = BoxSpec::uniform([-1.0; 3], [1.0; 3], [12; 3], shape).raw().unwrap();
        if jitter > 0.0 {
            perturb(&mut raw, jitter, 5);
        }
        let mesh = Mesh::build(raw).unwrap();
        let adjacency = &NodeEdges::build(&mesh);
        let (x, t) = icosphere(2, 0.45);
        let t: Vec<[u32; 4]> = t.iter().map(|t| [t[0], t[1], t[2], u32::MAX]).collect();
        let mut bodies: Vec<Surface> = (0..4)
            .map(|step| {
                let c = [-0.3 + 0.17 * step as f64, 0.05 * step as f64, 0.021];
                let x = x.iter().map(|p| add(rotate([0.0, 1.0, 1.0], 0.3 * step as f64, *p), c));
                surface(x.collect(), &t)
            })
            .collect();
        bodies.push(shell());
        for s in &bodies {
            let cuts = brute_force_cuts(&mesh, s, 0.0);
            let corner = (0..mesh.n_nodes()).find(|&k| mesh.coords[k] == [-1.0; 3]).unwrap();
            let outer = flood_fill(&mesh, &cuts, corner);
            let p_star =
                prescribe(&mesh, &cuts, &outer, |x| 1e5 * (1.0 + x[0] - 0.3 * x[1] * x[2]));
            let side: Vec<u32> = outer.iter().map(|&o| o as u32).collect();
            let view = LoadView {
                mesh: &mesh,
                adjacency,
                surface: s,
                t: 0.0,
                side: &side,
                cuts: &cuts,
                p_star: &p_star,
            };
            let mut restricted = vec![[0.0; 3]; s.n_nodes()];
            nodal_loads(LoadAlgorithm::Reconstructed, &view, &mut restricted).unwrap();
            let mut full = vec![[0.0; 3]; s.n_nodes()];
            // Every cell's cut edges, found by searching the whole edge and cut lists.
            let mut every: Vec<(u32, u32)> = Vec::new();
            for (c, cell) in mesh.cells.iter().enumerate() {
                for &[a, b] in cell.kind.edges() {
                    let (p, q) = (cell.nodes[a], cell.nodes[b]);
                    let Ok(e) = mesh.edges.binary_search(&[p.min(q), p.max(q)]) else { continue };
                    if let Ok(k) = cuts.binary_search_by_key(&(e as u32), |c| c.edge) {
                        every.push((c as u32, k as u32));
                    }
                }
            }
            every.sort_unstable();
            assert_eq!(every, reconstructed::cut_cells(&view), "{shape:?}: the cut cells' pairs");
            reconstructed::vertex_loads_in(&view, &every, |_, f, tri, bary| {
                distribute(s, tri, bary, f, &mut full)
            });
            let bits = |v: &[[f64; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&restricted), bits(&full), "{shape:?}");
            assert!(restricted.iter().flatten().any(|&f| f.abs() > 1.0), "{shape:?}: no load");
            let visited = reconstructed::cut_cells(&view).chunk_by(|a, b| a.0 == b.0).count();
            assert!(5 * visited < mesh.cells.len(), "{shape:?}: {visited} of {}", mesh.cells.len());
        }
    }
}
