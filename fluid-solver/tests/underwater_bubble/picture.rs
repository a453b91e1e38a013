//! The pressure on the symmetry plane `z = 0` of the bubble's octant, as a PNG.

use crate::common::plot::diverging;
use plotters::prelude::*;
use std::path::Path;

/// The interval a node at `x` covers on its axis (sorted node coordinates `axis`): from the
/// midpoint towards the previous node to the midpoint towards the next.
fn dual_interval(axis: &[f64], x: f64) -> (f64, f64) {
    let k = axis.partition_point(|&a| a < x - 1e-12);
    let lo = if k == 0 { x } else { 0.5 * (axis[k - 1] + x) };
    let hi = if k + 1 >= axis.len() { x } else { 0.5 * (axis[k + 1] + x) };
    (lo, hi)
}

/// Draws `p - p_inf` at the nodes of the plane `z = 0` inside `[0, extent]²` (each node's dual
/// rectangle, blue below the ambient pressure, red above, scaled to the largest `|p - p_inf|`
/// drawn) and the quarter circle of the bubble's equivalent radius `radius`; returns that
/// scale.
pub fn draw_pressure(
    path: &Path,
    coords: &[[f64; 3]],
    pressure: &[f64],
    p_inf: f64,
    extent: f64,
    radius: f64,
    caption: &str,
) -> anyhow::Result<f64> {
    let on_plane: Vec<usize> = (0..coords.len())
        .filter(|&i| coords[i][2].abs() < 1e-12 && coords[i][0] <= extent && coords[i][1] <= extent)
        .collect();
    anyhow::ensure!(!on_plane.is_empty(), "no node on the plane z = 0");
    let mut axis: Vec<f64> = on_plane.iter().map(|&i| coords[i][0]).collect();
    axis.sort_by(f64::total_cmp);
    axis.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let scale = on_plane.iter().map(|&i| (pressure[i] - p_inf).abs()).fold(0.0, f64::max);
    let root = BitMapBackend::new(path, (820, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let mm = 1e3;
    let caption = format!("{caption} (±{:.2} MPa, blue-red)", scale * 1e-6);
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(48)
        .build_cartesian_2d(0.0..extent * mm, 0.0..extent * mm)?;
    chart.configure_mesh().disable_mesh().x_desc("x (mm)").y_desc("y (mm)").draw()?;
    chart.draw_series(on_plane.iter().map(|&i| {
        let [x, y, _] = coords[i];
        let (x0, x1) = dual_interval(&axis, x);
        let (y0, y1) = dual_interval(&axis, y);
        let c = diverging((pressure[i] - p_inf) / scale.max(1e-300));
        Rectangle::new([(x0 * mm, y0 * mm), (x1 * mm, y1 * mm)], c.filled())
    }))?;
    let arc = (0..=90).map(|k| {
        let a = (k as f64).to_radians();
        (radius * a.cos() * mm, radius * a.sin() * mm)
    });
    chart.draw_series(LineSeries::new(arc, BLACK.stroke_width(2)))?;
    root.present()?;
    Ok(scale)
}
