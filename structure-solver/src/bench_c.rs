//! `structure-solver bench`, the C reference of the BT4 row: `bench/bt4.c`, the same explicit
//! step in C (built by `build.rs`), run as a separate program on the bench plate in the same
//! bench run, its timing and end positions read back.

use serde::Serialize;

use crate::bench::{Bt4Explicit, Bt4Plate};

/// The C reference `bench/bt4.c` (gcc -O3 -march=native -ffp-contract=off, blocked by 8).
#[derive(Debug, Serialize)]
pub struct CReference {
    /// Why it did not run (no C compiler at build time, or it failed).
    pub unavailable: Option<String>,
    pub element_updates_per_s: Option<f64>,
    pub element_updates_per_cpu_s: Option<f64>,
    /// Rust on one thread (natural order) over C: above 1 when Rust is faster.
    pub rust_over_c: Option<f64>,
    /// The same per second of processor time.
    pub rust_over_c_cpu: Option<f64>,
    /// Largest difference of the end positions of the C and the Rust run, relative to the
    /// largest coordinate (round-off: the same operations in the same order).
    pub position_difference: Option<f64>,
}

/// Runs the C reference on `plate` (`warmup` untimed and `steps` timed steps): its seconds
/// and end positions. The input file: 8 `u64` (magic, nodes, elements, points, Newton
/// updates, warm-up steps, timed steps, scaled rotary inertia), 15 `f64` (`C00 C01 C22 κG E
/// c1 c2 H σy r tol c 12κG ρ dt0`), the points and weights, positions, velocities and inverse
/// masses per node, thickness and connectivity (`u32`) per element.
pub fn c_reference(
    plate: &Bt4Plate,
    warmup: usize,
    steps: usize,
) -> anyhow::Result<(f64, f64, Vec<[f64; 3]>)> {
    use crate::elements::section::SHEAR_FACTOR;
    use crate::elements::RotaryInertia;
    use anyhow::Context;
    let exe = env!("BT4_C_REFERENCE");
    anyhow::ensure!(!exe.is_empty(), "bench/bt4.c was not compiled (no C compiler at build time)");
    let sim = Bt4Explicit::new(plate);
    let (bt4, set) = (&sim.bt4, &sim.bt4.settings);
    let m = bt4.materials()[0];
    let el = m.elastic;
    let c = el.tangent_plane_stress();
    let ret = m.plane_stress_constants::<f64>();
    let mut buf: Vec<u8> = Vec::new();
    let header = [
        0x3146_4552_4334_4254u64,
        plate.x0.len() as u64,
        plate.conn.len() as u64,
        set.rule.len() as u64,
        set.newton as u64,
        warmup as u64,
        steps as u64,
        u64::from(set.rotary == RotaryInertia::Scaled),
    ];
    header.iter().for_each(|v| buf.extend(v.to_le_bytes()));
    let consts = [
        c[0][0],
        c[0][1],
        c[2][2],
        SHEAR_FACTOR * el.shear_modulus(),
        el.e,
        ret.c1,
        ret.c2,
        ret.h,
        ret.sigma_y,
        set.hourglass,
        set.return_tol,
        el.plate_wave_speed(),
        12.0 * SHEAR_FACTOR * el.shear_modulus(),
        el.rho,
        sim.dt,
    ];
    let reals = consts
        .iter()
        .chain(&set.rule.points)
        .chain(&set.rule.weights)
        .chain(sim.x.iter().flatten())
        .chain(&sim.v)
        .chain(&sim.inv_mass)
        .chain(&bt4.thickness);
    reals.for_each(|v| buf.extend(v.to_le_bytes()));
    bt4.conn.iter().flatten().for_each(|v| buf.extend(v.to_le_bytes()));
    let dir = std::env::temp_dir();
    let tag = format!("bt4-c-{}", std::process::id());
    let (input, output) = (dir.join(format!("{tag}.in")), dir.join(format!("{tag}.out")));
    std::fs::write(&input, &buf).with_context(|| format!("writing {}", input.display()))?;
    let run = std::process::Command::new(exe).arg(&input).arg(&output).output();
    let _ = std::fs::remove_file(&input);
    let run = run.with_context(|| format!("running {exe}"))?;
    anyhow::ensure!(run.status.success(), "{exe}: {}", String::from_utf8_lossy(&run.stderr));
    let report: serde_json::Value = serde_json::from_slice(&run.stdout)?;
    let secs = report["seconds"].as_f64().context("the C reference printed no seconds")?;
    let cpu = report["cpu_seconds"].as_f64().context("the C reference printed no cpu_seconds")?;
    let bytes = std::fs::read(&output).with_context(|| format!("reading {}", output.display()))?;
    let _ = std::fs::remove_file(&output);
    anyhow::ensure!(
        bytes.len() == 24 * plate.x0.len(),
        "the C reference wrote {} bytes",
        bytes.len()
    );
    let x = bytes
        .chunks_exact(24)
        .map(|p| {
            std::array::from_fn(|k| f64::from_le_bytes(p[8 * k..8 * k + 8].try_into().unwrap()))
        })
        .collect();
    Ok((secs, cpu, x))
}
