//! The `structure-solver` command line on the cases of `cases/structure-*`: the suddenly
//! loaded cantilever against its closed-form dynamic peak, the clamped J2 plate under a pressure
//! pulse (where it yields, its permanent set and the energy plasticity takes), bad input named
//! by field, and the bench smoke run printing JSON. The static cases are in `static_cases.rs`.

mod common;

use common::cli::{cases, exe, fails, probes, table};
use std::path::PathBuf;

fn case_dir() -> PathBuf {
    cases("structure-cantilever-plate")
}

#[test]
fn suddenly_loaded_cantilever_peaks_at_twice_the_static_deflection() {
    let out = tempfile::tempdir().unwrap();
    let status = exe()
        .args(["run", case_dir().join("case.toml").to_str().unwrap(), "--out"])
        .arg(out.path())
        .args(["--set", "structure.t_end=0.034", "--set", "structure.output_every=5", "--quiet"])
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let csv = std::fs::read_to_string(out.path().join("structure_probes.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "time,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz");
    let uz: Vec<f64> = lines.map(|l| l.split(',').nth(3).unwrap().parse().unwrap()).collect();
    let peak = uz.iter().cloned().fold(f64::MIN, f64::max);
    let (p, l, e, i) = (30.0, 1.0, 200e9, 0.1 * 0.02f64.powi(3) / 12.0);
    let delta = p * l * l * l / (3.0 * e * i);
    println!(
        "cantilever: peak tip deflection {peak:.4e} m vs 2δ = {:.4e} m ({:+.2}%)",
        2.0 * delta,
        100.0 * (peak / (2.0 * delta) - 1.0)
    );
    assert!((peak / (2.0 * delta) - 1.0).abs() < 0.05);
}

#[test]
fn a_bad_dof_name_is_reported_with_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(case_dir().join("case.toml"))
        .unwrap()
        .replace("dof = \"uz\"", "dof = \"w\"");
    let path = dir.path().join("case.toml");
    std::fs::write(&path, text).unwrap();
    let out = exe()
        .args(["run", path.to_str().unwrap(), "--quiet", "--out"])
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("case.toml")
            && err.contains("case.toml:25:7: field `structure.loads[0].dof`")
            && err.contains("`w`"),
        "{err}"
    );
}

#[test]
fn bench_prints_json_with_both_measurements() {
    let out = exe().args(["bench", "--quick"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["explicit_bt4"]["element_updates_per_s_per_core"].as_f64().unwrap() > 0.0);
    assert!(v["explicit_bt4"]["plastic_fraction"].as_f64().unwrap() > 0.5);
    assert!(v["implicit_newmark"]["seconds_per_step"].as_f64().unwrap() > 0.0);
    // natural and shuffled numbering, as given and renumbered, on 1 and 2 threads
    let runs = v["explicit_bt4"]["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 8);
    let locality = &v["explicit_bt4"]["locality"];
    let numberings = locality["numberings"].as_array().unwrap();
    let profile = |order: &str, renumbered: bool| {
        let n = numberings.iter().find(|n| n["order"] == order && n["renumbered"] == renumbered);
        n.unwrap()["profile"].as_f64().unwrap()
    };
    assert!(profile("shuffled", true) < 0.5 * profile("shuffled", false));
    assert_eq!(profile("shuffled", true), profile("natural", true));
    assert!(locality["renumbered_over_as_given_shuffled"]["wall"].as_f64().unwrap() > 0.0);
}

/// Mean and RMS about the mean of the centre deflection after `t0` (many periods of the
/// plate's free vibration: the mean is the permanent set).
fn mean_and_rms(rows: &[Vec<f64>], t0: f64) -> (f64, f64) {
    let w: Vec<f64> = rows.iter().filter(|r| r[0] > t0).map(|r| r[3]).collect();
    let mean = w.iter().sum::<f64>() / w.len() as f64;
    let var = w.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / w.len() as f64;
    (mean, var.sqrt())
}

#[test]
fn pressure_pulse_yields_a_clamped_plate_where_the_moments_peak() {
    let out = tempfile::tempdir().unwrap();
    let rows = probes("structure-plastic-plate", out.path(), &[]);
    let (header, cells) = table(&out.path().join("structure_cells.csv"));
    assert_eq!(header, ["cell", "x", "y", "z", "plastic_strain", "von_mises"]);
    let ep = |x: f64, y: f64| {
        let c = cells.iter().find(|c| (c[1] - x).abs() < 1e-6 && (c[2] - y).abs() < 1e-6).unwrap();
        c[4]
    };
    // The quarter plate [0, 0.1]², clamped at x = 0 and y = 0, 10 x 10 cells of 1 cm: the
    // moments peak at the clamped edges' mid-spans and at the centre, and vanish at the corner.
    let (edge_mid, centre) = (ep(0.005, 0.095), ep(0.095, 0.095));
    let corner = (0..3)
        .flat_map(|i| (0..3).map(move |j| (0.005 + 0.01 * i as f64, 0.005 + 0.01 * j as f64)))
        .map(|(x, y)| ep(x, y))
        .fold(0.0, f64::max);
    let max = cells.iter().map(|c| c[4]).fold(0.0, f64::max);
    // the plate is symmetric about the diagonal x = y
    let asym = cells.iter().map(|c| (c[4] - ep(c[2], c[1])).abs()).fold(0.0, f64::max);
    println!("plastic strain: edge mid-span {edge_mid:.3e}, centre {centre:.3e}, corner 3x3 {corner:.1e}, max {max:.3e}, x-y asymmetry {asym:.1e}");
    assert!(edge_mid > 1e-3 && centre > 1e-3, "the edge mid-span and the centre must yield");
    assert_eq!(corner, 0.0, "the corner must stay elastic");
    assert!(asym < 1e-2 * max);
    // The same pulse on an elastic plate: it rings about zero; the J2 plate keeps a permanent
    // set along the pressure (+z) and rings less (plastic work taken from the pulse's energy).
    let (set, rms) = mean_and_rms(&rows, 3e-3);
    let out = tempfile::tempdir().unwrap();
    let elastic = ["--set", "structure.materials.steel.sigma_y=1e12"];
    let rows = probes("structure-plastic-plate", out.path(), &elastic);
    let (set_e, rms_e) = mean_and_rms(&rows, 3e-3);
    println!("centre after the pulse: J2 mean {set:.3e} m, rms {rms:.3e} m; elastic mean {set_e:.3e} m, rms {rms_e:.3e} m");
    assert!(set > 1e-4 && set > 4.0 * set_e.abs(), "permanent set {set:e}, elastic {set_e:e}");
    assert!(rms < 0.75 * rms_e);
    // MITC4 shells with J2 integrated through the thickness agree with BT4
    let out = tempfile::tempdir().unwrap();
    let mitc4 =
        "structure.parts=[{ element = \"mitc4\", material = \"steel\", thickness = 0.002 }]";
    let rows = probes("structure-plastic-plate", out.path(), &["--set", mitc4]);
    let (set_m, _) = mean_and_rms(&rows, 3e-3);
    let (_, cells) = table(&out.path().join("structure_cells.csv"));
    let corner_m =
        cells.iter().filter(|c| c[1] < 0.03 && c[2] < 0.03).map(|c| c[4]).fold(0.0, f64::max);
    println!("MITC4 J2: permanent set {set_m:.3e} m ({:+.2}% of BT4), corner 3x3 plastic strain {corner_m:.1e}", 100.0 * (set_m / set - 1.0));
    assert!((set_m / set - 1.0).abs() < 0.1 && corner_m == 0.0);
}
#[test]
fn semantic_errors_name_the_field_and_what_was_expected() {
    let plate = "structure-plastic-plate";
    let static_ = "structure-static-cantilever";
    let checks: [(&str, &str, &str, &[&str]); 6] = [
        // an unknown set lists the known ones
        (
            plate,
            "element = \"bt4\"",
            "element = \"bt4\"\nset = \"skin\"",
            &[
                "structure.parts[0].set",
                "no set \"skin\"; known sets: all, u0, u1, v0, v1, x0, x1, y0, y1",
            ],
        ),
        // a triangle element on quadrilaterals
        (
            plate,
            "element = \"bt4\"",
            "element = \"dkt\"",
            &[
                "structure.parts[0].element",
                "dkt needs triangles; cell 0 of set \"all\" is a quad4",
            ],
        ),
        // a static run of explicit-only shells
        (
            plate,
            "integrator = \"central_difference\"",
            "integrator = \"static\"",
            &["structure.integrator", "bt4 shells are explicit"],
        ),
        // an unknown set in a boundary condition
        (plate, "set = \"x1\"", "set = \"x2\"", &["structure.bc[2].set", "no set \"x2\""]),
        // a parse error: line, column and field
        (
            static_,
            "element = \"mitc4\"",
            "element = \"mitc8\"",
            &["case.toml:19:", "structure.parts[0].element", "mitc8", "dkt"],
        ),
        // the control node's set must hold one node
        (
            static_,
            "steps = 6",
            "steps = 6\ncontrol = { set = \"tip\", dof = \"uz\", value = 0.1 }",
            &["structure.control.set", "one node, \"tip\" holds 3"],
        ),
    ];
    for (case, from, to, words) in checks {
        let err = fails(case, from, to);
        for w in words {
            assert!(err.contains(w), "the error lacks `{w}`: {err}");
        }
    }
}
