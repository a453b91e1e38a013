//! `fsi plot DIR`: one PNG per probe column of the run's probe files (`probes.csv`,
//! `structure_probes.csv`), against time. Plain line plots for a first look; ParaView is the tool
//! for fields.

use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The probe files `fsi plot` reads, in the order it reads them.
pub const PROBE_FILES: &[&str] = &["probes.csv", "structure_probes.csv"];

/// A probe file: column names and rows of numbers, the first column the time.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

/// Reads a probe CSV (header line, then numbers); errors name the file and line.
pub fn read_csv(path: &Path) -> anyhow::Result<Table> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let (_, header) =
        lines.next().ok_or_else(|| anyhow::anyhow!("{}: empty file", path.display()))?;
    let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
    let mut rows = Vec::new();
    for (i, line) in lines {
        let row: Vec<f64> = line
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| anyhow::anyhow!("{}:{}: {e}", path.display(), i + 1))?;
        anyhow::ensure!(
            row.len() == columns.len(),
            "{}:{}: {} values, the header names {}",
            path.display(),
            i + 1,
            row.len(),
            columns.len()
        );
        rows.push(row);
    }
    Ok(Table { columns, rows })
}

/// Writes `plots/<file stem>-<column>.png` in `dir` for every probe column; returns the files.
pub fn plot_dir(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let found: Vec<PathBuf> =
        PROBE_FILES.iter().map(|f| dir.join(f)).filter(|p| p.is_file()).collect();
    anyhow::ensure!(
        !found.is_empty(),
        "{} holds no probe file (looked for {})",
        dir.display(),
        PROBE_FILES.join(", ")
    );
    let plots = dir.join("plots");
    std::fs::create_dir_all(&plots)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", plots.display()))?;
    for file in found {
        let table = read_csv(&file)?;
        let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        for c in 1..table.columns.len() {
            let name = table.columns[c].replace(['/', ' '], "_");
            let png = plots.join(format!("{stem}-{name}.png"));
            plot_column(&table, c, &png)?;
            written.push(png);
        }
    }
    Ok(written)
}

/// One column against time, 800 x 500 pixels.
fn plot_column(table: &Table, c: usize, png: &Path) -> anyhow::Result<()> {
    let points: Vec<(f64, f64)> = table.rows.iter().map(|r| (r[0], r[c])).collect();
    let (t0, t1) = range(points.iter().map(|p| p.0));
    let (y0, y1) = range(points.iter().map(|p| p.1));
    let root = BitMapBackend::new(png, (800, 500)).into_drawing_area();
    let draw = |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: {e}", png.display());
    root.fill(&WHITE).map_err(|e| draw(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&table.columns[c], ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(t0..t1, y0..y1)
        .map_err(|e| draw(&e))?;
    chart
        .configure_mesh()
        .x_desc(table.columns[0].as_str())
        .y_desc(table.columns[c].as_str())
        .draw()
        .map_err(|e| draw(&e))?;
    chart.draw_series(LineSeries::new(points, &BLUE)).map_err(|e| draw(&e))?;
    root.present().map_err(|e| draw(&e))?;
    Ok(())
}

/// Finite min and max of `values`, widened when flat or empty so the axis is never degenerate.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { lo.abs().max(1.0) * 0.05 };
    (lo - pad, hi + pad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_every_probe_column_of_a_run_folder() {
        let dir = tempfile::tempdir().unwrap();
        let mut csv = String::from("time,piston.ux,piston.vx\n");
        for i in 0..50 {
            let t = i as f64 * 1e-3;
            csv += &format!("{t},{},{}\n", (100.0 * t).sin(), 100.0 * (100.0 * t).cos());
        }
        std::fs::write(dir.path().join("structure_probes.csv"), csv).unwrap();
        let files = plot_dir(dir.path()).unwrap();
        assert_eq!(files.len(), 2);
        for f in &files {
            let bytes = std::fs::read(f).unwrap();
            assert_eq!(&bytes[1..4], b"PNG", "{}", f.display());
            assert!(bytes.len() > 2000, "{} is nearly empty", f.display());
        }
    }

    #[test]
    fn bad_rows_name_the_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("probes.csv"), "time,a.p\n0,1\n0.1,x\n").unwrap();
        let e = plot_dir(dir.path()).unwrap_err().to_string();
        assert!(e.contains("probes.csv:3"), "{e}");
        let empty = tempfile::tempdir().unwrap();
        let e = plot_dir(empty.path()).unwrap_err().to_string();
        assert!(e.contains("no probe file"), "{e}");
    }

    #[test]
    fn flat_and_empty_ranges_are_widened() {
        assert_eq!(range([2.0, 2.0].into_iter()), (1.9, 2.1));
        assert_eq!(range(std::iter::empty()), (0.0, 1.0));
        assert_eq!(range([f64::NAN, 0.0, 10.0].into_iter()), (-0.5, 10.5));
    }
}
