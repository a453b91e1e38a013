//! Shared helpers of the structure tests: load-deflection tables against published references.
#![allow(dead_code)]

pub mod cli;

use structure_solver::model::Model;
use structure_solver::statics::{load_steps, NewtonSettings};

/// A published load-deflection table.
pub struct Table<'a> {
    pub name: &'a str,
    pub columns: &'a [&'a str],
    /// `(P / P_max, reference values)`
    pub rows: &'a [(f64, &'a [f64])],
}

/// Translational displacement of `node` in the model's current state.
pub fn displacement(m: &dyn Model, node: usize) -> [f64; 3] {
    let mut u = vec![[0.0; 3]; m.n_nodes()];
    m.displacement(&mut u);
    u[node]
}

/// Runs the model through the table's load factors (load factor = pseudo-time), measures after
/// every tabulated step, prints computed / reference / error and returns the relative errors.
pub fn run_table(
    model: &mut dyn Model,
    table: &Table,
    measure: impl Fn(&dyn Model) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let targets: Vec<f64> = table.rows.iter().map(|r| r.0).collect();
    let s = NewtonSettings { tol: 1e-6, max_iter: 40, max_cuts: 10 };
    let mut got = Vec::new();
    load_steps(model, &targets, &s, |m, _| got.push(measure(&*m)))
        .unwrap_or_else(|e| panic!("{}: {e}", table.name));
    println!("{}: P/Pmax, {:?} (computed / reference / relative error)", table.name, table.columns);
    let mut errors = Vec::new();
    for ((lf, refs), v) in table.rows.iter().zip(&got) {
        let e: Vec<f64> = v.iter().zip(refs.iter()).map(|(a, b)| (a - b) / b).collect();
        let cols: Vec<String> = v
            .iter()
            .zip(refs.iter())
            .zip(&e)
            .map(|((a, b), e)| format!("{a:.4} / {b:.4} / {:+.2}%", 100.0 * e))
            .collect();
        println!("  {lf:.3}: {}", cols.join(",  "));
        errors.push(e);
    }
    errors
}

/// Largest absolute relative error over all rows and columns.
pub fn max_error(errors: &[Vec<f64>]) -> f64 {
    errors.iter().flatten().fold(0.0f64, |a, e| a.max(e.abs()))
}
