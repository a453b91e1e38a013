//! `fsi plot DIR [--reference COLUMN=FILE]...`: one PNG per probe column of the run's probe files
//! (`probes.csv`, `structure_probes.csv`), against time, with a published or exact history drawn
//! beside a column where one is given (a CSV of time and one value column, `#` lines comments).
//! Plain line plots for a first look; ParaView is the tool for fields.

use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The probe files `fsi plot` reads, in the order it reads them.
pub const PROBE_FILES: &[&str] = &["probes.csv", "structure_probes.csv"];

/// A probe file: column names and rows of numbers, the first column the time.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
    /// 1-based number of a last line left without its line break (a writer killed mid-row):
    /// it is not in `rows`.
    pub cut_line: Option<usize>,
}

/// Reads a probe CSV (header line, then numbers); errors name the file and line. A last line
/// without its terminating line break was cut short by a writer that died: it is left out and
/// reported in [`Table::cut_line`], since even when it parses its last number may be cut.
pub fn read_csv(path: &Path) -> anyhow::Result<Table> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    let (whole, cut_line) = match text.rfind('\n') {
        _ if text.is_empty() || text.ends_with('\n') => (text.as_str(), None),
        Some(i) => (&text[..=i], Some(text[..=i].matches('\n').count() + 1)),
        None => ("", Some(1)),
    };
    let mut lines =
        whole.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| match cut_line {
        Some(_) => anyhow::anyhow!("{}:1: the header line is cut short", path.display()),
        None => anyhow::anyhow!("{}: empty file", path.display()),
    })?;
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
    Ok(Table { columns, rows, cut_line })
}

/// The warning for a table whose last line was cut, naming the file and line.
pub fn cut_warning(path: &Path, table: &Table) -> Option<String> {
    table.cut_line.map(|line| {
        format!(
            "{}:{line}: the last line is cut short (the writer stopped mid-row); plotting the {} \
             whole rows before it",
            path.display(),
            table.rows.len()
        )
    })
}

/// A history to draw beside a probe column: `COLUMN=FILE` on the command line.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// The probe column it goes with (`tip.ux`).
    pub column: String,
    /// Its label (the file's stem) and points (time, value: the file's first two columns).
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

impl Reference {
    /// Parses `COLUMN=FILE` and reads the file; errors name the argument or the file and line.
    pub fn parse(arg: &str) -> anyhow::Result<Reference> {
        let (column, file) = arg.split_once('=').ok_or_else(|| {
            anyhow::anyhow!("--reference `{arg}`: expected COLUMN=FILE, e.g. tip.ux=m2c-tip.csv")
        })?;
        let path = Path::new(file);
        let table = read_csv(path)?;
        anyhow::ensure!(
            table.columns.len() >= 2,
            "{}: a reference needs a time column and a value column",
            path.display()
        );
        let label = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let points = table.rows.iter().map(|r| (r[0], r[1])).collect();
        Ok(Reference { column: column.to_string(), label, points })
    }
}

/// Writes `plots/<file stem>-<column>.png` in `dir` for every probe column, with the
/// `references` of that column beside it; returns the files.
pub fn plot_dir(dir: &Path, references: &[Reference]) -> anyhow::Result<Vec<PathBuf>> {
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
        if let Some(w) = cut_warning(&file, &table) {
            eprintln!("fsi: warning: {w}");
        }
        let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        for c in 1..table.columns.len() {
            let name = table.columns[c].replace(['/', ' '], "_");
            let png = plots.join(format!("{stem}-{name}.png"));
            let beside: Vec<&Reference> =
                references.iter().filter(|r| r.column == table.columns[c]).collect();
            plot_column(&table, c, &beside, &png)?;
            written.push(png);
        }
    }
    Ok(written)
}

/// One column against time, 800 x 500 pixels, with its references (red points, a legend).
fn plot_column(
    table: &Table,
    c: usize,
    references: &[&Reference],
    png: &Path,
) -> anyhow::Result<()> {
    let points: Vec<(f64, f64)> = table.rows.iter().map(|r| (r[0], r[c])).collect();
    let all = || points.iter().chain(references.iter().flat_map(|r| r.points.iter()));
    let (t0, t1) = range(all().map(|p| p.0));
    let (y0, y1) = range(all().map(|p| p.1));
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
    let (x_ticks, y_ticks) = (TickFormat::for_range(t0, t1), TickFormat::for_range(y0, y1));
    chart
        .configure_mesh()
        .x_desc(axis_label(&table.columns[0]))
        .y_desc(axis_label(&table.columns[c]))
        .x_label_formatter(&|v| x_ticks.label(*v))
        .y_label_formatter(&|v| y_ticks.label(*v))
        .draw()
        .map_err(|e| draw(&e))?;
    let line = chart.draw_series(LineSeries::new(points, &BLUE)).map_err(|e| draw(&e))?;
    if !references.is_empty() {
        line.label("this run").legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE));
        for r in references {
            let marks = r.points.iter().map(|&p| Circle::new(p, 4, RED.filled()));
            chart
                .draw_series(marks)
                .map_err(|e| draw(&e))?
                .label(r.label.as_str())
                .legend(|(x, y)| Circle::new((x + 10, y), 4, RED.filled()));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| draw(&e))?;
    }
    root.present().map_err(|e| draw(&e))?;
    Ok(())
}

/// The unit of a probe column from its component name (`<probe>.<component>` or `time`).
pub fn unit(column: &str) -> Option<&'static str> {
    match column.rsplit('.').next().unwrap_or(column) {
        "time" | "t" => Some("s"),
        "rho" => Some("kg/m³"),
        "vx" | "vy" | "vz" => Some("m/s"),
        "p" => Some("Pa"),
        "ux" | "uy" | "uz" => Some("m"),
        _ => None,
    }
}

/// `piston.ux [m]`, or the bare name when the unit is unknown.
pub fn axis_label(column: &str) -> String {
    match unit(column) {
        Some(u) => format!("{column} [{u}]"),
        None => column.to_string(),
    }
}

/// Tick labels of one axis in engineering notation (`-6.70e-6`, `100.02e3`): the exponent a
/// multiple of 3 fixed by the largest magnitude on the axis, with at least 3 significant digits
/// and enough decimals to tell ticks a tenth of the range apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickFormat {
    exp: i32,
    decimals: usize,
}

impl TickFormat {
    /// The format for an axis from `lo` to `hi`.
    pub fn for_range(lo: f64, hi: f64) -> TickFormat {
        let big = lo.abs().max(hi.abs());
        if !big.is_finite() || big == 0.0 {
            return TickFormat { exp: 0, decimals: 1 };
        }
        let lead = big.log10().floor() as i32;
        let exp = 3 * lead.div_euclid(3);
        // 3 significant digits of the largest value...
        let mut decimals = 2 - (lead - exp);
        // ...and the leading digit of a tenth of the span.
        let step = (hi - lo).abs() / 10.0;
        if step.is_finite() && step > 0.0 {
            decimals = decimals.max(exp - step.log10().floor() as i32);
        }
        TickFormat { exp, decimals: decimals.clamp(0, 12) as usize }
    }

    /// The label of `v`; a value that rounds to zero is `0`, never `-0.0`.
    pub fn label(&self, v: f64) -> String {
        let m = v / 10f64.powi(self.exp);
        let text = format!("{m:.*}", self.decimals);
        if text.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
            return "0".to_string();
        }
        if self.exp == 0 {
            text
        } else {
            format!("{text}e{}", self.exp)
        }
    }
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
        let files = plot_dir(dir.path(), &[]).unwrap();
        assert_eq!(files.len(), 2);
        for f in &files {
            let bytes = std::fs::read(f).unwrap();
            assert_eq!(&bytes[1..4], b"PNG", "{}", f.display());
            assert!(bytes.len() > 2000, "{} is nearly empty", f.display());
        }
    }

    #[test]
    fn a_reference_is_drawn_beside_its_column() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("structure_probes.csv"), "time,tip.ux\n0,0\n1,1\n2,4\n")
            .unwrap();
        let file = dir.path().join("published.csv");
        std::fs::write(&file, "# a published history\ntime,ux\n0.5,0.2\n1.5,2.0\n").unwrap();
        let r = Reference::parse(&format!("tip.ux={}", file.display())).unwrap();
        assert_eq!((r.label.as_str(), r.points.len()), ("published", 2));
        let plain = plot_dir(dir.path(), &[]).unwrap();
        let plain = std::fs::read(&plain[0]).unwrap();
        let with = plot_dir(dir.path(), &[r]).unwrap();
        assert_ne!(std::fs::read(&with[0]).unwrap(), plain, "the reference changed nothing");
        let e = Reference::parse("tip.ux").unwrap_err().to_string();
        assert!(e.contains("COLUMN=FILE"), "{e}");
        let e = Reference::parse("tip.ux=/no/such.csv").unwrap_err().to_string();
        assert!(e.contains("/no/such.csv"), "{e}");
    }

    #[test]
    fn bad_rows_name_the_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("probes.csv"), "time,a.p\n0,1\n0.1,x\n").unwrap();
        let e = plot_dir(dir.path(), &[]).unwrap_err().to_string();
        assert!(e.contains("probes.csv:3"), "{e}");
        let empty = tempfile::tempdir().unwrap();
        let e = plot_dir(empty.path(), &[]).unwrap_err().to_string();
        assert!(e.contains("no probe file"), "{e}");
    }

    #[test]
    fn a_cut_last_line_is_left_out_with_a_warning_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("structure_probes.csv");
        // The last row stopped inside its last number: it even parses, to a wrong value.
        let text = "time,piston.ux\n0,1e-3\n0.001,2e-3\n0.002,3.0";
        std::fs::write(&path, text).unwrap();
        let table = read_csv(&path).unwrap();
        assert_eq!(table.rows, vec![vec![0.0, 1e-3], vec![0.001, 2e-3]]);
        assert_eq!(table.cut_line, Some(4));
        let w = cut_warning(&path, &table).unwrap();
        assert!(w.contains("structure_probes.csv:4") && w.contains("cut short"), "{w}");
        assert_eq!(plot_dir(dir.path(), &[]).unwrap().len(), 1);
        // Cut in the middle of a row: the same.
        std::fs::write(&path, "time,piston.ux\n0,1e-3\n0.00").unwrap();
        assert_eq!(read_csv(&path).unwrap().cut_line, Some(3));
        assert_eq!(plot_dir(dir.path(), &[]).unwrap().len(), 1);
        // A whole file has no warning; a bad row that is whole stays an error.
        std::fs::write(&path, "time,piston.ux\n0,1e-3\n").unwrap();
        let table = read_csv(&path).unwrap();
        assert_eq!((table.rows.len(), cut_warning(&path, &table)), (1, None));
        std::fs::write(&path, "time,piston.ux\n0,1e-3\n0.1\n").unwrap();
        let e = read_csv(&path).unwrap_err().to_string();
        assert!(e.contains("structure_probes.csv:3"), "{e}");
        std::fs::write(&path, "time,pis").unwrap();
        let e = read_csv(&path).unwrap_err().to_string();
        assert!(e.contains("structure_probes.csv:1") && e.contains("header"), "{e}");
    }

    #[test]
    fn small_ticks_are_not_rounded_to_zero() {
        let f = TickFormat::for_range(-7e-6, 0.0);
        assert_eq!(f.label(-6.7e-6), "-6.70e-6");
        assert_eq!(f.label(-1e-6), "-1.00e-6");
        assert_eq!(f.label(-1e-22), "0");
        assert_eq!(f.label(0.0), "0");
        // Big values with small changes: every tick a tenth of the span apart stays distinct.
        let f = TickFormat::for_range(99_999.0, 100_001.0);
        let labels: Vec<String> = (0..=10).map(|i| f.label(99_999.0 + 0.2 * i as f64)).collect();
        assert_eq!(labels[0], "99.9990e3");
        for w in labels.windows(2) {
            assert_ne!(w[0], w[1], "{labels:?}");
        }
        assert_eq!(TickFormat::for_range(0.0, 1.0).label(0.5), "0.50");
        assert_eq!(TickFormat::for_range(-0.45, 0.45).label(-0.45), "-450e-3");
        assert_eq!(TickFormat::for_range(0.0, 0.0).label(0.0), "0");
    }

    #[test]
    fn axes_carry_the_unit_of_their_column() {
        assert_eq!(axis_label("time"), "time [s]");
        assert_eq!(axis_label("face.rho"), "face.rho [kg/m³]");
        assert_eq!(axis_label("face.vz"), "face.vz [m/s]");
        assert_eq!(axis_label("face.p"), "face.p [Pa]");
        assert_eq!(axis_label("piston.uy"), "piston.uy [m]");
        assert_eq!(axis_label("tip.sxx"), "tip.sxx");
    }

    #[test]
    fn flat_and_empty_ranges_are_widened() {
        assert_eq!(range([2.0, 2.0].into_iter()), (1.9, 2.1));
        assert_eq!(range(std::iter::empty()), (0.0, 1.0));
        assert_eq!(range([f64::NAN, 0.0, 10.0].into_iter()), (-0.5, 10.5));
    }
}
