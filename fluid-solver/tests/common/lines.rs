//! Reading the solver's CSV outputs (probe and line files) back in the tests.

use std::path::Path;

/// Rows of a CSV file as numbers, header skipped (a line file's columns are
/// `x,y,z,s,rho,vx,vy,vz,p,material,phi`).
pub fn rows(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|s| s.parse().unwrap()).collect())
        .collect()
}

/// Means of `(ρ, u, p)` over the line samples with `x` in `[a, b]` (more than 10 of them).
pub fn plateau(rows: &[Vec<f64>], a: f64, b: f64) -> [f64; 3] {
    let inside: Vec<&Vec<f64>> = rows.iter().filter(|r| (a..=b).contains(&r[0])).collect();
    assert!(inside.len() > 10, "{} samples in [{a}, {b}]", inside.len());
    let n = inside.len() as f64;
    [4, 5, 8].map(|k| inside.iter().map(|r| r[k]).sum::<f64>() / n)
}
