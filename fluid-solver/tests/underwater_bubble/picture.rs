//! The pressure on the symmetry plane `z = 0` of the bubble's octant, as a PNG.

use crate::common::plot::diverging;
use plotters::prelude::*;
use std::path::Path;

/// Draws `p - p_inf` over the cell faces `faces` (node lists) on the plane `z = 0` inside
/// `[0, extent]²` (each node's share of each face, from its corner to the face's centre and the
/// midpoints of its two sides: its dual cell's trace; blue below the ambient pressure, red
/// above, scaled to the largest `|p - p_inf|` drawn) and the quarter circle of the bubble's
/// equivalent radius `radius`; returns that scale.
pub fn draw_pressure(
    path: &Path,
    coords: &[[f64; 3]],
    faces: &[Vec<usize>],
    pressure: &[f64],
    p_inf: f64,
    extent: f64,
    radius: f64,
    caption: &str,
) -> anyhow::Result<f64> {
    let inside = |i: usize| coords[i][0] <= extent && coords[i][1] <= extent;
    let faces: Vec<&Vec<usize>> = faces.iter().filter(|f| f.iter().any(|&i| inside(i))).collect();
    anyhow::ensure!(!faces.is_empty(), "no cell face on the plane z = 0");
    let mut on_plane: Vec<usize> = faces.iter().flat_map(|f| f.iter().copied()).collect();
    on_plane.sort_unstable();
    on_plane.dedup();
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
    let at = |i: usize| (coords[i][0] * mm, coords[i][1] * mm);
    let mid = |a: (f64, f64), b: (f64, f64)| (0.5 * (a.0 + b.0), 0.5 * (a.1 + b.1));
    chart.draw_series(faces.iter().flat_map(|f| {
        let n = f.len() as f64;
        let centre = f.iter().fold((0.0, 0.0), |c, &i| (c.0 + at(i).0 / n, c.1 + at(i).1 / n));
        (0..f.len()).map(move |k| {
            let (prev, i, next) = (f[(k + f.len() - 1) % f.len()], f[k], f[(k + 1) % f.len()]);
            let corner = vec![centre, mid(at(prev), at(i)), at(i), mid(at(i), at(next))];
            let c = diverging((pressure[i] - p_inf) / scale.max(1e-300));
            Polygon::new(corner, c.filled())
        })
    }))?;
    let arc = (0..=90).map(|k| {
        let a = (k as f64).to_radians();
        (radius * a.cos() * mm, radius * a.sin() * mm)
    });
    chart.draw_series(LineSeries::new(arc, BLACK.stroke_width(2)))?;
    root.present()?;
    Ok(scale)
}
