//! Natural frequencies against theory, first three modes within 1%, lumped mass with physical
//! rotary inertia: an Euler-Bernoulli cantilever (beam elements) and a simply supported
//! rectangular plate (Kirchhoff: ω_mn = π² ((m/a)² + (n/b)²) √(D / ρh)) with quads and
//! triangles.

use structure_solver::assembly::{FeModel, Part};
use structure_solver::elements::{BeamSection, ShellSection};
use structure_solver::mesh::generate;
use structure_solver::modal::lowest_frequencies;

fn compare(name: &str, got: &[f64], want: &[f64]) {
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        let e = (g - w) / w;
        println!("{name} mode {}: ω = {g:.4} vs {w:.4} ({:+.3}%)", k + 1, 100.0 * e);
        assert!(e.abs() < 0.01, "{name} mode {}: {e:+.4}", k + 1);
    }
}

#[test]
fn cantilever_beam_bending_modes() {
    let (l, b, h, e, rho) = (1.0, 0.02, 0.01, 2e11, 7850.0);
    let sec = BeamSection::rectangle(e, 0.3, rho, b, h);
    let mesh = generate::line([0.0, 0.0, 0.0], [l, 0.0, 0.0], 40);
    let mut m = FeModel::new(&mesh, |_| Part::Beam(sec, [0.0, 1.0, 0.0])).unwrap();
    m.fix(mesh.node_set("start").unwrap(), [true; 6]);
    // bending in the x-z plane only: hold uy, θx, θz
    let all: Vec<usize> = (0..mesh.nodes.len()).collect();
    m.fix(&all, [false, true, false, true, false, true]);
    let got = lowest_frequencies(&mut m, 3).unwrap();
    let c = (e * sec.iy / (rho * sec.area * l.powi(4))).sqrt();
    let want: Vec<f64> =
        [1.875104069, 4.694091133, 7.854757438].iter().map(|bl: &f64| bl * bl * c).collect();
    compare("cantilever beam", &got, &want);
}

fn plate(triangles: bool) {
    let (a, b, h, e, nu, rho) = (2.0, 1.0, 0.01, 2e11, 0.3, 7850.0);
    let mut mesh = generate::rectangle(a, b, 32, 16);
    if triangles {
        mesh = mesh.to_triangles();
    }
    let sec = ShellSection { e, nu, rho, h };
    let mut m = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    let all: Vec<usize> = (0..mesh.nodes.len()).collect();
    m.fix(&all, [true, true, false, false, false, true]); // bending only
    for set in ["u0", "u1", "v0", "v1"] {
        m.fix(mesh.node_set(set).unwrap(), [false, false, true, false, false, false]);
    }
    let got = lowest_frequencies(&mut m, 3).unwrap();
    let d = e * h.powi(3) / (12.0 * (1.0 - nu * nu));
    let w = |mm: f64, nn: f64| {
        std::f64::consts::PI.powi(2)
            * ((mm / a).powi(2) + (nn / b).powi(2))
            * (d / (rho * h)).sqrt()
    };
    compare(
        if triangles { "SS plate triangles" } else { "SS plate quads" },
        &got,
        &[w(1.0, 1.0), w(2.0, 1.0), w(3.0, 1.0)],
    );
}

#[test]
fn simply_supported_plate_quads() {
    plate(false);
}

#[test]
fn simply_supported_plate_triangles() {
    plate(true);
}
