//! `cases/taylor-plate`: Taylor's (1941) air-backed plate through `fsi run` (real `fluid-solver`
//! and, as the structure, `rigid-structure` (`case.toml`) or `structure-solver` with one
//! stiff MITC4 shell free only in x (`case-shells.toml`); C0). A plane exponential wave p_i(t) = p_m e^{-t/θ} in water
//! hits a free plate of areal mass m with air at the water's ambient pressure behind it.
//!
//! Acoustic theory, with the water and the air at the same ambient p0 (no static load): the wet
//! face carries p0 + 2 p_i - ρ0 c0 v (incident plus reflected wave), the air face p0 + ρa ca v (the
//! compression wave the plate drives into the air), so
//!   m v' = 2 p_i(t) - Z v,  Z = ρ0 c0 + ρa ca,  v(0) = 0,
//!   v(t) = 2 p_m θ / (m (1 - β)) (e^{-β t/θ} - e^{-t/θ}),  β = Z θ / m.
//! It holds while the water at the wet face stays above the cut-off p_cut of the case:
//! p0 + 2 p_m e^{-t/θ} - ρ0 c0 v(t) = p_cut defines the cavitation time t_c, found here by
//! bisection; the velocity is checked on [0, t_c].
//!
//! Every parameter comes from the case file: c0 and ρ0 from the water's EOS and background state,
//! p_m and θ from the first and last wave regions (the nodal values of the incident wave), m from
//! the rigid mass, or the shell's ρ t times the area of its gmsh mesh, over the column's section.
//!
//! Build first: `cargo build --release -p coupler-scripts -p rigid-structure -p structure-solver
//! -p fluid-solver --bins`.

use fsi_system_tests::{Fsi, Probes, Scratch};
use interface_protocol::case::{Case, Region, StructureMesh};
use interface_protocol::io::gmsh;
use std::path::Path;
use std::time::Duration;

/// Taylor's problem as the case states it.
struct Taylor {
    /// Areal mass m [kg/m²].
    m: f64,
    /// Water and air impedances ρ c.
    z_water: f64,
    z_air: f64,
    p0: f64,
    p_m: f64,
    theta: f64,
    p_cut: f64,
}

impl Taylor {
    fn from_case(case: &Case) -> Taylor {
        let fluid = case.fluid.as_ref().expect("[fluid]");
        let float = |name: &str, key: &str| {
            fluid.fluids[name].eos.get(key).and_then(|v| v.as_float()).expect("an EOS constant")
        };
        let (gamma, p_c, gamma_air) =
            (float("water", "gamma"), float("water", "p_c"), float("air", "gamma"));
        let initial = fluid.initial.as_ref().expect("[fluid.initial]");
        let (rho0, p0) = (initial.state[0], initial.state[4]);
        let z_water = (gamma * (p0 + p_c) * rho0).sqrt();
        let c0 = z_water / rho0;
        // The wave regions (no fluid of their own), each x >= x_j - h/2 holding node x_j's state.
        let wave: Vec<(f64, f64)> = initial
            .regions
            .iter()
            .filter(|r| r.fluid.is_none())
            .map(|r| match r.region {
                Region::HalfSpace { point, .. } => (point[0], r.state[4]),
                _ => panic!("the wave regions are half spaces"),
            })
            .collect();
        let air = initial.regions.iter().find(|r| r.fluid.as_deref() == Some("air")).unwrap();
        let z_air = (gamma_air * air.state[4] * air.state[0]).sqrt();
        let mesh = fluid.mesh.as_ref().unwrap().box_mesh.as_ref().expect("a box mesh").clone();
        let h = (mesh.hi[0] - mesh.lo[0]) / mesh.cells[0] as f64;
        let section = (mesh.hi[1] - mesh.lo[1]) * (mesh.hi[2] - mesh.lo[2]);
        let (mass, x_p) = plate_mass_and_position(case);
        let ((xa, pa), (xb, pb)) = (wave[0], *wave.last().unwrap());
        let theta = (xb - xa) / (c0 * ((pb - p0) / (pa - p0)).ln());
        let p_m = (pb - p0) * ((x_p - (xb + h / 2.0)) / (c0 * theta)).exp();
        let p_cut = fluid.embedded.as_ref().and_then(|e| e.p_cut).unwrap_or(f64::NEG_INFINITY);
        Taylor { m: mass / section, z_water, z_air, p0, p_m, theta, p_cut }
    }

    fn beta(&self) -> f64 {
        (self.z_water + self.z_air) * self.theta / self.m
    }

    /// The closed-form plate velocity.
    fn velocity(&self, t: f64) -> f64 {
        let (b, th) = (self.beta(), self.theta);
        2.0 * self.p_m * th / (self.m * (1.0 - b)) * ((-b * t / th).exp() - (-t / th).exp())
    }

    /// The water's pressure on the wet face, p0 + 2 p_i - ρ0 c0 v.
    fn wet_pressure(&self, t: f64) -> f64 {
        self.p0 + 2.0 * self.p_m * (-t / self.theta).exp() - self.z_water * self.velocity(t)
    }

    /// The first time the wet-face pressure reaches p_cut (bisection), or `t_end`.
    fn cavitation(&self, t_end: f64) -> f64 {
        if self.wet_pressure(t_end) > self.p_cut {
            return t_end;
        }
        let (mut a, mut b) = (0.0, t_end);
        for _ in 0..100 {
            let mid = 0.5 * (a + b);
            if self.wet_pressure(mid) > self.p_cut {
                a = mid;
            } else {
                b = mid;
            }
        }
        a
    }
}

/// The plate's mass and its x: the rigid body's mass and reference, or the shell's ρ t times the
/// area of its (flat, x = const) gmsh mesh and that x.
fn plate_mass_and_position(case: &Case) -> (f64, f64) {
    let s = case.structure.as_ref().expect("[structure]");
    if let Some(body) = s.rigid.as_ref() {
        return (body.mass, body.reference[0]);
    }
    let Some(StructureMesh::Gmsh { file, .. }) = s.mesh.as_ref() else {
        panic!("the shell plate comes as a gmsh file");
    };
    let msh = gmsh::read(&case.dir().join(file), |_| Ok(())).expect("the plate mesh reads");
    let mut area = 0.0;
    for b in msh.blocks.iter().filter(|b| b.dim == 2) {
        let n = b.connectivity.len() / b.len();
        for e in b.connectivity.chunks(n) {
            // The polygon's area in the y-z plane (the shoelace formula).
            let p: Vec<[f64; 3]> = e.iter().map(|&k| msh.coords[k as usize]).collect();
            area += 0.5
                * (0..n)
                    .map(|i| {
                        let (a, b) = (p[i], p[(i + 1) % n]);
                        a[1] * b[2] - b[1] * a[2]
                    })
                    .sum::<f64>()
                    .abs();
        }
    }
    let rho = s.material.as_ref().expect("structure.material").rho;
    let t = s.thickness.expect("structure.thickness");
    (rho * t * area, msh.coords[0][0])
}

/// The plate's velocity: the rigid body's `plate.vx`, or the mean `vx` of the shell's nodes (its
/// momentum over its mass: the nodes carry equal masses).
fn plate_velocity(p: &Probes) -> Vec<(f64, f64)> {
    let nodes: Vec<usize> =
        (0..p.columns.len()).filter(|&c| p.columns[c].ends_with(".vx")).collect();
    assert!(!nodes.is_empty(), "no vx column among {:?}", p.columns);
    p.rows
        .iter()
        .map(|r| (r[0], nodes.iter().map(|&c| r[c]).sum::<f64>() / nodes.len() as f64))
        .collect()
}

#[test]
fn taylor_plate_follows_the_acoustic_closed_form_until_cavitation() {
    check_taylor_plate("case.toml");
}

#[test]
fn taylor_plate_with_a_structure_solver_shell_follows_the_closed_form() {
    check_taylor_plate("case-shells.toml");
}

fn check_taylor_plate(file: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/taylor-plate").join(file);
    let case = Case::load(&path, &[]).expect("the case parses");
    let taylor = Taylor::from_case(&case);
    let t_end = case.coupling.t_end;
    let t_c = taylor.cavitation(t_end);
    println!(
        "taylor-plate: p_m {:.6e} Pa, θ {:.6e} s, m {:.4} kg/m², β {:.5}, cavitation at {:.4e} s",
        taylor.p_m,
        taylor.theta,
        taylor.m,
        taylor.beta(),
        t_c
    );
    assert!(t_c < t_end, "the run reaches the cavitation time");
    let scratch = Scratch::new();
    let out = scratch.path().join("out");
    let done = Fsi::run(&scratch, &path, &out, &[]).wait(Duration::from_secs(120));
    assert!(done.status.success(), "{}", done.stderr);
    let series = plate_velocity(&Probes::read(&out.join("structure_probes.csv")));
    let last = series.last().expect("probe rows").0;
    assert!((last - t_end).abs() < 1e-12, "the run ended at {last}, not {t_end}");
    let peak = series.iter().map(|&(t, _)| taylor.velocity(t)).fold(0.0, f64::max);
    let (mut worst, mut at) = (0.0, 0.0);
    for &(t, v) in series.iter().filter(|&&(t, _)| t <= t_c) {
        let e = (v - taylor.velocity(t)).abs() / peak;
        if e > worst {
            (worst, at) = (e, t);
        }
    }
    let v_c = series.iter().rfind(|&&(t, _)| t <= t_c).unwrap();
    println!(
        "taylor-plate: peak {peak:.5} m/s; largest error {worst:.3e} of the peak at t = {at:.3e} s; \
         v({:.4e}) = {:.5} (exact {:.5})",
        v_c.0,
        v_c.1,
        taylor.velocity(v_c.0)
    );
    // A half coupling-step lag shifts v by v'(0) Δt/2 = p_m Δt / m, 2.7% of the peak here; a load
    // without the reflected wave (p_i instead of 2 p_i) is off by half, a wrong sign by all of it.
    let lag = taylor.p_m * case.coupling.dt / taylor.m / peak;
    println!("taylor-plate: a half-step lag would be {lag:.3e} of the peak");
    assert!(worst < 0.1 * lag, "largest error {worst:.3e} of the peak at t = {at:.3e}");

    // Past cavitation the water at the wet face holds p_cut and the air pushes back with
    // p0 + ρa ca v: m v' = p_cut - p0 - ρa ca v. The mean deceleration from t_c + 0.1 θ to t_end.
    let after: Vec<(f64, f64)> =
        series.iter().copied().filter(|&(t, _)| t >= t_c + 0.1 * taylor.theta).collect();
    let ((ta, va), (tb, vb)) = (after[0], *after.last().unwrap());
    let measured = (vb - va) / (tb - ta);
    let expected = (taylor.p_cut - taylor.p0 - taylor.z_air * 0.5 * (va + vb)) / taylor.m;
    println!("taylor-plate: after cavitation v' = {measured:.5} m/s² (expected {expected:.5})");
    assert!((measured / expected - 1.0).abs() < 1e-3, "v' {measured} against {expected}");
}
