//! A level set together with an embedded surface (thesis §3.3.2 with Ch. 4-5, DESIGN §5):
//! - a cut edge whose two ends hold different fluids takes Alg. 5.1 on both sides, each with its
//!   own EOS (the special-edge lists, and a water | air pressure jump held by a static plate
//!   whose residual vanishes, where the two-phase flux would not);
//! - a uniform flow carrying a water | air interface at equal p and u past a static plate
//!   parallel to it stays uniform to round-off while the interface moves with the flow;
//! - water | interface | gas on a tube with a shell moving at 10 m/s in the water, before its
//!   waves reach the interface: both sides of the shell against the exact one-sided Riemann
//!   solutions, the gas and the interface untouched, and the state bitwise the run's without the
//!   level set;
//! - `cases/shell-water-air` with the level set on (the interface on the shell, the swept nodes
//!   changing fluid): bitwise the state without it, `φ` consistent with the materials.

mod common;

use common::lines::{plateau, rows as line};
use fluid_solver::bc::BoundaryCondition;
use fluid_solver::embedded::generate::plate;
use fluid_solver::embedded::step::{EmbeddedStep, Wall};
use fluid_solver::embedded::tracker::{Seed, Tracker};
use fluid_solver::embedded::Surface;
use fluid_solver::eos::Eos;
use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
use fluid_solver::mesh::Mesh;
use fluid_solver::riemann::{RiemannSolution, State1d};
use fluid_solver::semidiscretization::{Numerics, Semidiscretization};
use fluid_solver::setup::{self, Mode};
use fluid_solver::solver::{self, read_checkpoint, RunOptions};
use fluid_solver::special_edges::SpecialKind;
use fluid_solver::state::{State, Workspace};
use interface_protocol::case::{Case, InterfaceTreatment, Tracking};
use std::path::{Path, PathBuf};

const WATER: Eos = Eos::StiffenedGas { gamma: 7.15, p_c: 2.89e8 };
const AIR: Eos = Eos::PerfectGas { gamma: 1.4 };

/// Water (material 0) left of a static plate at x = 0.537 and right of x = 0.85, air (1) between;
/// water at 3e7 Pa on the left, 1e5 Pa elsewhere, all at rest. Every edge the plate cuts joins
/// water and air and is of kind `Cut`; the uncut water | air edges at x = 0.85 stay
/// `TwoMaterial`. With Alg. 5.1 on both sides of the cut edges each node sees its own pressure at
/// the wall, so the residual vanishes to round-off; the two-phase flux there (the operator
/// without the wall) would not hold the jump.
#[test]
fn a_cut_edge_between_two_fluids_takes_alg_5_1_on_both_sides() {
    let spec = BoxSpec::uniform([0.0; 3], [1.0, 0.4, 0.4], [10, 4, 4], BoxCells::Tet);
    let mesh = Mesh::build(spec.raw().unwrap()).unwrap();
    let s = plate([0.537, -0.1, -0.1], [0.0, 0.6, 0.0], [0.0, 0.0, 0.6], [2, 2]);
    let surface = Surface::new(&s.elements, s.x.clone(), 0).unwrap();
    let seeds = [
        Seed { point: [0.1, 0.2, 0.2], fluid: true },
        Seed { point: [0.9, 0.2, 0.2], fluid: true },
    ];
    let tracker = Tracker::new(&mesh, surface, Tracking::Collision, &seeds).unwrap();
    assert!(tracker.active.iter().all(|&a| a));
    let material: Vec<u8> =
        mesh.coords.iter().map(|x| u8::from(x[0] > 0.537 && x[0] < 0.85)).collect();
    let prim: Vec<[f64; 5]> = mesh
        .coords
        .iter()
        .zip(&material)
        .map(|(x, &m)| match (m, x[0] < 0.537) {
            (0, true) => [1000.0, 0.0, 0.0, 0.0, 3e7],
            (0, false) => [1000.0, 0.0, 0.0, 0.0, 1e5],
            _ => [1.2, 0.0, 0.0, 0.0, 1e5],
        })
        .collect();
    let walls: Vec<(String, BoundaryCondition)> =
        FACE_NAMES.iter().map(|f| (f.to_string(), BoundaryCondition::SlipWall)).collect();
    let semi = Semidiscretization::with_materials(
        mesh,
        vec![WATER, AIR],
        material.clone(),
        Numerics::default(),
        &walls,
    )
    .unwrap();
    let mesh = &semi.mesh;
    let step = EmbeddedStep::new(&semi, &tracker, None, InterfaceTreatment::SecondOrder);
    let (mut cut_two_fluid, mut uncut_two_fluid) = (0, 0);
    for s in step.special().all() {
        let [i, j] = mesh.edges[s.edge as usize].map(|v| v as usize);
        let cut = tracker.cuts.find(s.edge).is_some();
        let two_fluid = material[i] != material[j];
        match (cut, two_fluid) {
            (true, _) => {
                assert_eq!(s.kind, SpecialKind::Cut, "cut edge {}", s.edge);
                cut_two_fluid += usize::from(two_fluid);
            }
            (false, true) => {
                assert_eq!(s.kind, SpecialKind::TwoMaterial, "edge {}", s.edge);
                uncut_two_fluid += 1;
            }
            (false, false) => panic!("edge {} is special but neither cut nor two-fluid", s.edge),
        }
    }
    let n_cut = step.special().all().iter().filter(|s| s.kind == SpecialKind::Cut).count();
    assert_eq!(n_cut, tracker.cuts.cuts.len(), "every cut edge is listed once");
    assert_eq!(cut_two_fluid, n_cut, "the plate separates the fluids");
    assert!(n_cut > 50 && uncut_two_fluid > 50, "{n_cut} cut, {uncut_two_fluid} uncut two-fluid");
    let cons: Vec<[f64; 5]> =
        prim.iter().zip(&material).map(|(w, &m)| semi.eos[m as usize].prim_to_cons(w)).collect();
    let mut ws = Workspace::new(mesh.n_nodes());
    let scale = 3e7
        * mesh
            .edge_normals
            .iter()
            .map(|n| n.iter().map(|c| c * c).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
    let largest = |ws: &Workspace| {
        ws.residual.iter().flat_map(|r| r[1..4].iter().map(|c| c.abs())).fold(0.0, f64::max)
    };
    let wall = Wall { step: &step, tracker: &tracker, t: 0.0 };
    let mut none = vec![(); mesh.n_nodes()];
    semi.primitives(&cons, &mut ws).unwrap();
    semi.residual_and_update_with(&mut ws, &mut none, |_, _, _| {}, Some(wall)).unwrap();
    let with_wall = largest(&ws) / scale;
    semi.residual(&cons, &mut ws).unwrap();
    let two_phase = largest(&ws) / scale;
    println!(
        "{n_cut} cut water | air edges, {uncut_two_fluid} uncut: momentum residual {with_wall:.2e} \
         with Alg. 5.1, {two_phase:.2e} with the two-phase flux (of 3e7 Pa |ν|max)"
    );
    assert!(with_wall < 1e-12, "the plate does not hold the jump: {with_wall:e}");
    assert!(two_phase > 1e-2, "the two-phase flux holds it too: {two_phase:e}");
}

/// The final state of a run, its node positions and the material id of its water.
struct Ran {
    state: State,
    x: Vec<[f64; 3]>,
    water: u8,
}

/// Runs the case text `text` (written to `dir/name.toml`, with `overrides`) into `dir/name`
/// ([`run_path`]).
fn run_text(dir: &Path, name: &str, text: &str, overrides: &[String]) -> Ran {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    run_path(&path, text, overrides, &dir.join(name))
}

/// Runs the case file `path` with `overrides` into `out`; checks the final `φ` against the
/// materials when the case has a level set.
fn run_path(path: &Path, text: &str, overrides: &[String], out: &Path) -> Ran {
    let case = Case::load(path, overrides).unwrap();
    let opts = RunOptions { out: out.to_path_buf(), quiet: true, restart: None, force: false };
    let summary = solver::run(&case, text, &opts).unwrap();
    let (state, _, _) = read_checkpoint(out, summary.nodes).unwrap();
    let problem = setup::problem(&case, Mode::Alone).unwrap();
    if let Some(ls) = &problem.level_set {
        ls.check(&state)
            .unwrap_or_else(|e| panic!("{}: φ and the materials disagree: {e}", out.display()));
    }
    println!("{}: {} steps", out.display(), summary.steps);
    let water = problem.fluid_names.iter().position(|n| n == "water").unwrap() as u8;
    Ran { state, x: problem.semi.mesh.coords.clone(), water }
}

/// The number of nodes whose conserved state or material differ between two states.
fn differing(a: &State, b: &State) -> usize {
    let cons = a
        .cons
        .iter()
        .zip(&b.cons)
        .filter(|(x, y)| x.iter().zip(y.iter()).any(|(p, q)| p.to_bits() != q.to_bits()));
    cons.count() + a.material.iter().zip(&b.material).filter(|(x, y)| x != y).count()
}

/// Air (x < 0.23) and water at 1e5 Pa moving at 100 m/s along x past a static plate in the
/// plane y = 0.213 across the box, to t = 3e-3 (the interface moves 0.3, through the plate's
/// cut edges, which join water and air where it passes): every node keeps p and u to round-off
/// and holds its fluid's density, and the interface is within two cells of x = 0.53.
#[test]
fn a_uniform_flow_carries_the_interface_past_a_parallel_wall_at_round_off() {
    let dir = tempfile::tempdir().unwrap();
    let (air, water) = ([1.2, 100.0, 0.0, 0.0, 1e5], [1000.0, 100.0, 0.0, 0.0, 1e5]);
    let text = format!(
        r#"
[fluid.fluids.water]
eos = {{ kind = "stiffened_gas", gamma = 7.15, p_c = 2.89e8 }}
[fluid.fluids.air]
eos = {{ kind = "perfect_gas", gamma = 1.4 }}
[fluid.mesh]
box = {{ lo = [0, 0, 0], hi = [1, 0.4, 0.2], cells = [20, 8, 4], shape = "tet" }}
[fluid.initial]
fluid = "water"
state = {water:?}
regions = [{{ region = {{ shape = "half_space", point = [0.23, 0.0, 0.0], normal = [-1.0, 0.0, 0.0] }}, fluid = "air", state = {air:?} }}]
[fluid.level_set]
reinit_every = 5
[fluid.boundary]
xmin = {{ kind = "far_field", state = {air:?} }}
xmax = {{ kind = "far_field", state = {water:?} }}
ymin = {{ kind = "symmetry" }}
ymax = {{ kind = "symmetry" }}
zmin = {{ kind = "symmetry" }}
zmax = {{ kind = "symmetry" }}
[fluid.embedded]
surface = {{ generator = "plate", corner = [-0.5, 0.213, -0.5], edge_u = [2.0, 0.0, 0.0], edge_v = [0.0, 0.0, 1.2], cells = [2, 2] }}
tracking = "collision"
seeds = [{{ at = [0.9, 0.1, 0.1], active = true }}, {{ at = [0.9, 0.3, 0.1], active = true }}]
[fluid.time]
t_end = 3e-3
[output]
fields_every = 0
checkpoint_every = 0
"#
    );
    let Ran { state, x, water: water_id } = run_text(dir.path(), "uniform", &text, &[]);
    let (mut dp, mut du, mut drho) = (0.0f64, 0.0f64, 0.0f64);
    let (mut air_nodes, mut misplaced) = (0, 0);
    let front = 0.23 + 100.0 * 3e-3;
    for (i, q) in state.cons.iter().enumerate() {
        let is_air = state.material[i] != water_id;
        let (eos, w0) = if is_air { (AIR, air) } else { (WATER, water) };
        let w = eos.cons_to_prim(q);
        dp = dp.max((w[4] - 1e5).abs() / 1e5);
        du = du.max((1..4).map(|k| (w[k] - w0[k]).abs() / 100.0).fold(0.0, f64::max));
        drho = drho.max((w[0] - w0[0]).abs() / w0[0]);
        air_nodes += usize::from(is_air);
        let far = (x[i][0] - front).abs() > 2.0 * 0.05;
        misplaced += usize::from(far && is_air != (x[i][0] < front));
    }
    println!(
        "uniform flow past the plate: |Δp|/p <= {dp:.1e}, |Δu|/|u| <= {du:.1e}, |Δρ|/ρ <= \
         {drho:.1e}; {air_nodes} air nodes, {misplaced} off the interface by more than 2h"
    );
    assert!(dp < 1e-10 && du < 1e-10 && drho < 1e-10, "p {dp:e}, u {du:e}, ρ {drho:e}");
    assert_eq!(misplaced, 0);
    // The interface moved: about 0.53 of the 1.0 long box is air (11 of 21 planes of 45 nodes).
    assert!((10 * 45..=12 * 45).contains(&air_nodes), "{air_nodes} air nodes");
}

const SHELL_X0: f64 = -4.99;
const SHELL_SPEED: f64 = 10.0;
const T_TUBE: f64 = 3e-3;
const GAS: [f64; 5] = [100.0, 0.0, 0.0, 0.0, 3e7];

/// Water at rest at 3e7 Pa on [-12, 3], gas at the same pressure on [3, 8], 399 cells; a shell at
/// x = -4.99 moving at 10 m/s in the water; with `level_set`, `[fluid.level_set]`.
fn tube_text(level_set: bool) -> String {
    let ls = if level_set { "[fluid.level_set]\nreinit_every = 5\n" } else { "" };
    format!(
        r#"
[fluid]
lines = [{{ name = "axis", from = [-12.0, 0.0, 0.0], to = [8.0, 0.0, 0.0], points = 2001, times = [{T_TUBE:e}] }}]
[fluid.fluids.water]
eos = {{ kind = "stiffened_gas", gamma = 7.15, p_c = 2.89e8 }}
[fluid.fluids.gas]
eos = {{ kind = "perfect_gas", gamma = 1.4 }}
[fluid.mesh]
box = {{ lo = [-12.0, -0.05, -0.05], hi = [8.0, 0.05, 0.05], cells = [399, 1, 1], shape = "tet" }}
[fluid.initial]
fluid = "water"
state = [1000.0, 0.0, 0.0, 0.0, 3e7]
regions = [{{ region = {{ shape = "half_space", point = [3.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}, fluid = "gas", state = {GAS:?} }}]
{ls}
[fluid.boundary]
xmin = {{ kind = "far_field", state = [1000.0, 0.0, 0.0, 0.0, 3e7] }}
xmax = {{ kind = "far_field", state = {GAS:?} }}
ymin = {{ kind = "symmetry" }}
ymax = {{ kind = "symmetry" }}
zmin = {{ kind = "symmetry" }}
zmax = {{ kind = "symmetry" }}
[fluid.embedded]
surface = {{ generator = "plate", corner = [{SHELL_X0}, -0.1, -0.1], edge_u = [0.0, 0.2, 0.0], edge_v = [0.0, 0.0, 0.2], cells = [1, 1] }}
motion = {{ kind = "translation", velocity = [{SHELL_SPEED}, 0.0, 0.0] }}
tracking = "collision"
seeds = [{{ at = [-8.0, 0.0, 0.0], active = true }}, {{ at = [-2.0, 0.0, 0.0], active = true }}]
[fluid.numerics]
flux = "roe"
limiter = "van_albada"
cfl = 0.5
[fluid.time]
t_end = {T_TUBE:e}
[output]
fields_every = 0
checkpoint_every = 0
"#
    )
}

/// The first sample from `from` towards `to` where `p` passes `level`.
fn crossing(rows: &[Vec<f64>], level: f64, from: f64, to: f64) -> f64 {
    let mut inside: Vec<&Vec<f64>> =
        rows.iter().filter(|r| r[0] >= from.min(to) && r[0] <= from.max(to)).collect();
    if from > to {
        inside.reverse();
    }
    let start = inside[0][8] > level;
    inside.iter().find(|r| (r[8] > level) != start).map(|r| r[0]).expect("no crossing")
}

/// Water | interface | gas with a shell moving at 10 m/s in the water, to t = 3e-3: the
/// rarefaction behind the shell and the shock ahead of it (at x ≈ -0.45) have not reached the
/// interface at x = 3. Both sides' plateaus within 0.5% of each jump of the exact one-sided
/// Riemann solutions, the shock and the middle of the rarefaction within 2 cells, the gas and the
/// interface exactly as they started, and the whole state bitwise that of the run without the
/// level set (whose interface cannot move).
#[test]
fn a_shell_in_water_beside_a_gas_interface_matches_the_exact_solution() {
    let dir = tempfile::tempdir().unwrap();
    let Ran { state: with, x, water } = run_text(dir.path(), "with", &tube_text(true), &[]);
    let without = run_text(dir.path(), "without", &tube_text(false), &[]).state;
    let differ = differing(&with, &without);
    println!("level set on vs off: {differ} nodes differ");
    assert_eq!(differ, 0, "the level set changed the flow");
    for (i, &m) in with.material.iter().enumerate() {
        assert_eq!(m != water, x[i][0] > 3.0, "node {i} at {:?} changed fluid", x[i]);
    }
    let rows = line(&dir.path().join(format!("with/lines/axis_t{T_TUBE:.6e}.csv")));
    let w0 = State1d { rho: 1000.0, u: 0.0, p: 3e7 };
    let behind = RiemannSolution::wall(&WATER, w0, SHELL_SPEED).unwrap();
    // Ahead of the shell: the mirror image of water left of a wall at -10 m/s.
    let ahead = RiemannSolution::wall(&WATER, w0, -SHELL_SPEED).unwrap();
    let dx = 20.0 / 399.0;
    let (b, a) = (plateau(&rows, -8.8, -5.3), plateau(&rows, -4.4, -1.2));
    println!(
        "behind the shell {b:?} (exact ρ {} p {}), ahead {a:?} (exact ρ {} p {})",
        behind.star.rho_l, behind.star.p, ahead.star.rho_l, ahead.star.p
    );
    let close = |got: f64, exact: f64, jump: f64, name: &str| {
        let e = (got - exact).abs() / jump.abs();
        assert!(e < 5e-3, "{name}: {got} vs exact {exact}: {e:.2e} of the jump {jump}");
    };
    close(b[0], behind.star.rho_l, behind.star.rho_l - 1000.0, "ρ behind");
    close(b[1], SHELL_SPEED, SHELL_SPEED, "u behind");
    close(b[2], behind.star.p, behind.star.p - 3e7, "p behind");
    close(a[0], ahead.star.rho_l, ahead.star.rho_l - 1000.0, "ρ ahead");
    close(a[1], SHELL_SPEED, SHELL_SPEED, "u ahead");
    close(a[2], ahead.star.p, ahead.star.p - 3e7, "p ahead");
    let shock = SHELL_X0 - ahead.left_wave().0 * T_TUBE;
    let got = crossing(&rows, 0.5 * (3e7 + ahead.star.p), 2.5, SHELL_X0 + 0.5);
    println!("shock at {got}, exact {shock}");
    assert!((got - shock).abs() < 2.0 * dx, "shock at {got}, exact {shock}");
    let (head, tail) = behind.left_wave();
    let middle = SHELL_X0 + 0.5 * (head + tail) * T_TUBE;
    let got = crossing(&rows, 0.5 * (3e7 + behind.star.p), -11.5, SHELL_X0 - 0.5);
    println!("rarefaction middle at {got}, exact {middle}");
    assert!((got - middle).abs() < 2.0 * dx, "rarefaction middle at {got}, exact {middle}");
    // The gas and the water next to the interface have not moved (x > 2: beyond the reach of the
    // shock's numerical precursor, 48 cells ahead of it).
    let mut worst = 0.0f64;
    for (i, q) in with.cons.iter().enumerate().filter(|(i, _)| x[*i][0] > 2.0) {
        let (eos, w0) = match with.material[i] == water {
            true => (WATER, [1000.0, 0.0, 0.0, 0.0, 3e7]),
            false => (AIR, GAS),
        };
        let w = eos.cons_to_prim(q);
        worst = worst.max((w[0] - w0[0]).abs() / w0[0]).max((w[4] - 3e7).abs() / 3e7);
        worst = worst.max((1..4).map(|k| w[k].abs() / SHELL_SPEED).fold(0.0, f64::max));
    }
    println!("beyond x = 2: largest relative change {worst:.1e}");
    assert!(worst < 1e-12, "the interface region changed by {worst:e}");
}

fn shell_case() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/shell-water-air/case.toml")
}

/// `cases/shell-water-air` (water | shell | air, the shell moving into the air at 10 m/s) on 399
/// cells from x = -15.03 (a grid plane at x = 0.0225, which the shell passes) to t = 3.5e-3
/// with the level set on: the interface is the shell, the nodes it sweeps
/// change from air to water and take a water `φ`, and the state is bitwise that without the
/// level set, with `φ` consistent with every material.
#[test]
fn shell_water_air_with_the_level_set_is_the_run_without_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = shell_case();
    let text = std::fs::read_to_string(&path).unwrap();
    let base = [
        "fluid.mesh.box.cells=[399, 1, 1]".to_string(),
        "fluid.mesh.box.lo=[-15.03, -0.05, -0.05]".into(),
        "fluid.time.t_end=3.5e-3".into(),
    ];
    let mut on = base.to_vec();
    on.push("fluid.level_set={ reinit_every = 5 }".into());
    let Ran { state: with, x, water } = run_path(&path, &text, &on, &dir.path().join("with"));
    let without = run_path(&path, &text, &base, &dir.path().join("without")).state;
    let differ = differing(&with, &without);
    let swept = (0..x.len()).filter(|&i| x[i][0] > 0.0 && with.material[i] == water).count();
    println!("shell-water-air, level set on vs off: {differ} nodes differ; {swept} swept nodes now water");
    assert!(swept >= 4, "{swept} nodes swept");
    assert_eq!(differ, 0, "the level set changed the flow");
}
